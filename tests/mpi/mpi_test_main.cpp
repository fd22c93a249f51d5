// main() of the tests that run inside mpirun (tests/mpi/*_mpitest.cpp): every rank runs the whole suite, and
// the process fails when any rank failed, so that ctest sees a failure on rank 1 too.
#include <gtest/gtest.h>

#include "mpi/session.h"

int main(int argc, char** argv) {
  const raysift::mpi::Session session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int failed = RUN_ALL_TESTS() != 0 ? 1 : 0;
  return raysift::mpi::max_all(failed) > 0 ? 1 : 0;
}
