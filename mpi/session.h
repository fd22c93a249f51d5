#pragma once
/// \file The MPI session every distributed command uses, with <mpi.h> kept out of the header: a build without
/// MPI (RAYSIFT_MPI off) links the same API as a one-rank session, so callers need no #ifdef.
///
///   mpi::Session session(&argc, &argv);   // main(): MPI_Init when started by mpirun/srun, MPI_Finalize on exit
///   if (mpi::is_root()) write_outputs();  // rank 0 alone writes outputs and stats
///   mpi::all_or_none([&] { read_my_brick(); });  // a failure on any rank throws RankFailure on every rank
///
/// Failure rule (the "all-ranks abort"): a step that may fail on some ranks only (reading a brick) runs inside
/// all_or_none(); every rank then agrees, and every rank throws RankFailure carrying the lowest failing rank's
/// message. main() wraps the whole command in all_or_none(), prints the message on rank 0 only and every rank
/// exits with the same non-zero code, so the user sees ONE message. Collective calls must only be made where
/// every rank reaches them, i.e. after the fallible local steps have been agreed.
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "core/span.h"

namespace raysift::mpi {

/// Initialises MPI for the process's lifetime (RAII). Only when the process was started by an MPI launcher
/// (Open MPI's mpirun, PMIx or Slurm's srun set the environment): a plain `raysift render` does not pay for
/// MPI_Init and stays a one-rank run. Without MPI support it does nothing.
class Session {
 public:
  Session(int* argc, char*** argv);
  ~Session();  ///< MPI_Finalize
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

/// True when this build has MPI support (RAYSIFT_MPI).
bool built_with_mpi();
int rank();  ///< 0 without MPI or outside a Session
int size();  ///< 1 without MPI or outside a Session
inline bool is_root() { return rank() == 0; }

void barrier();

/// Root's bytes on every rank (the others' `bytes` is replaced).
void broadcast(std::vector<std::uint8_t>& bytes, int root = 0);
/// Root's JSON on every rank (sent as its text).
Json broadcast_json(const Json& value, int root = 0);
/// On `root`: every rank's bytes, by rank. Elsewhere: empty.
std::vector<std::vector<std::uint8_t>> gather(const std::vector<std::uint8_t>& bytes, int root = 0);
/// On `root`: every rank's JSON as an array, by rank. Elsewhere: an empty array.
Json gather_json(const Json& value, int root = 0);
/// Sends `out` to `peer` and receives `in.size()` floats from it (one MPI_Sendrecv; blocks).
void exchange(int peer, Span<const float> out, Span<float> in);
void send(int peer, Span<const float> out);
void receive(int peer, Span<float> in);
/// Sum / max over ranks, on every rank.
double sum_all(double value);
double max_all(double value);
double min_all(double value);
/// Element-wise sum over ranks of equally long arrays, in place on every rank (exact: integers).
void sum_all(std::vector<std::uint64_t>& values);

/// Bytes this rank has sent and received through this API since the session began.
struct Traffic {
  std::uint64_t sent = 0, received = 0;
};
Traffic traffic();

/// Thrown on every rank by all_or_none() when a step failed somewhere. what() is the message of the lowest
/// failing rank, prefixed "rank R: " when the run has several ranks and R is not 0.
struct RankFailure : std::runtime_error {
  RankFailure(const std::string& message, int exit_code) : std::runtime_error(message), exit_code(exit_code) {}
  int exit_code;  ///< 2 for a UsageError on the failing rank (as one process), else 1
};

/// Runs `step`; with several ranks, every rank then learns whether it threw anywhere and, if so, throws
/// RankFailure (collective: every rank must call it). With one rank the step's own exception passes through.
void all_or_none(const std::function<void()>& step);

}  // namespace raysift::mpi
