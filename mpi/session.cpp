#include "mpi/session.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "core/errors.h"

#if RAYSIFT_HAVE_MPI
#include <mpi.h>
#endif

namespace raysift::mpi {

namespace {

struct State {
  bool active = false;  ///< MPI_Init was called by a Session and MPI_Finalize not yet
  int rank = 0, size = 1;
  Traffic traffic;
};
State& state() {
  static State s;
  return s;
}

/// Open MPI's mpirun, PMIx launchers (srun --mpi=pmix) and MPICH/Hydra or PMI-1 launchers set one of these.
bool launched_by_mpi_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

std::vector<std::uint8_t> to_bytes(const std::string& s) { return {s.begin(), s.end()}; }
std::string to_string(const std::vector<std::uint8_t>& b) { return {b.begin(), b.end()}; }

#if RAYSIFT_HAVE_MPI
// MPI counts are int: move anything larger in pieces of at most 1 GiB.
constexpr std::size_t kChunk = std::size_t(1) << 30;

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw IoError(std::string("MPI ") + what + " failed (error " + std::to_string(code) + ")");
}
#endif

}  // namespace

Session::Session(int* argc, char*** argv) {
#if RAYSIFT_HAVE_MPI
  if (!launched_by_mpi_launcher()) return;
  int provided = 0;
  // Only the main thread calls MPI; TBB workers never do.
  check(MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  State& s = state();
  s.active = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &s.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &s.size);
#else
  (void)argc;
  (void)argv;
  if (launched_by_mpi_launcher())  // every process would render the whole frame alone and write the same files
    std::cerr << "raysift: warning: started by an MPI launcher, but this build has no MPI (RAYSIFT_MPI=OFF): each "
                 "process runs as a separate one-rank job\n";
#endif
}

Session::~Session() {
#if RAYSIFT_HAVE_MPI
  if (state().active) MPI_Finalize();
  state() = State{};
#endif
}

bool built_with_mpi() { return RAYSIFT_HAVE_MPI != 0; }
int rank() { return state().rank; }
int size() { return state().size; }

void barrier() {
#if RAYSIFT_HAVE_MPI
  if (size() > 1) check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
#endif
}

void broadcast(std::vector<std::uint8_t>& bytes, int root) {
#if RAYSIFT_HAVE_MPI
  if (size() == 1) return;
  unsigned long long n = bytes.size();
  check(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, root, MPI_COMM_WORLD), "MPI_Bcast");
  bytes.resize(n);
  for (std::size_t at = 0; at < n; at += kChunk)
    check(MPI_Bcast(bytes.data() + at, int(std::min<std::size_t>(kChunk, n - at)), MPI_BYTE, root, MPI_COMM_WORLD),
          "MPI_Bcast");
  if (rank() == root) state().traffic.sent += n * std::uint64_t(size() - 1);
  else state().traffic.received += n;
#else
  (void)bytes;
  (void)root;
#endif
}

Json broadcast_json(const Json& value, int root) {
  if (size() == 1) return value;
  std::vector<std::uint8_t> bytes = rank() == root ? to_bytes(value.dump()) : std::vector<std::uint8_t>{};
  broadcast(bytes, root);
  return Json::parse(to_string(bytes));
}

std::vector<std::vector<std::uint8_t>> gather(const std::vector<std::uint8_t>& bytes, int root) {
  if (size() == 1) return {bytes};
#if RAYSIFT_HAVE_MPI
  // Gathers are for small messages (stats, error texts); images go through send/receive.
  RAYSIFT_CHECK(bytes.size() < kChunk);
  int n = int(bytes.size());
  std::vector<int> counts(rank() == root ? size() : 0), offsets(counts.size());
  check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, MPI_COMM_WORLD), "MPI_Gather");
  std::size_t total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    offsets[r] = int(total);
    total += std::size_t(counts[r]);
  }
  std::vector<std::uint8_t> all(total);
  check(MPI_Gatherv(bytes.data(), n, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, root,
                    MPI_COMM_WORLD), "MPI_Gatherv");
  std::vector<std::vector<std::uint8_t>> out;
  if (rank() != root) {
    state().traffic.sent += std::uint64_t(n);
    return out;
  }
  state().traffic.received += total - std::uint64_t(n);
  for (std::size_t r = 0; r < counts.size(); ++r)
    out.emplace_back(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
  return out;
#else
  (void)root;
  return {bytes};
#endif
}

Json gather_json(const Json& value, int root) {
  Json out = Json::array();
  for (const auto& bytes : gather(to_bytes(value.dump()), root)) out.push_back(Json::parse(to_string(bytes)));
  return out;
}

void exchange(int peer, Span<const float> out, Span<float> in) {
#if RAYSIFT_HAVE_MPI
  const std::size_t n = std::max(out.size(), in.size());
  constexpr std::size_t chunk = kChunk / sizeof(float);
  for (std::size_t at = 0; at < n; at += chunk) {
    const int s = int(out.size() > at ? std::min(chunk, out.size() - at) : 0);
    const int r = int(in.size() > at ? std::min(chunk, in.size() - at) : 0);
    check(MPI_Sendrecv(out.data() + std::min(at, out.size()), s, MPI_FLOAT, peer, 0,
                       in.data() + std::min(at, in.size()), r, MPI_FLOAT, peer, 0, MPI_COMM_WORLD,
                       MPI_STATUS_IGNORE), "MPI_Sendrecv");
  }
  state().traffic.sent += out.size() * sizeof(float);
  state().traffic.received += in.size() * sizeof(float);
#else
  (void)peer;
  (void)out;
  (void)in;
  throw InvalidInput("mpi::exchange needs an MPI build");
#endif
}

void send(int peer, Span<const float> out) { exchange(peer, out, {}); }
void receive(int peer, Span<float> in) { exchange(peer, {}, in); }

namespace {
enum class Reduction { Sum, Max, Min };
double reduce(double value, [[maybe_unused]] Reduction op) {
#if RAYSIFT_HAVE_MPI
  if (size() == 1) return value;
  double result = 0;
  const MPI_Op mpi_op = op == Reduction::Sum ? MPI_SUM : op == Reduction::Max ? MPI_MAX : MPI_MIN;
  check(MPI_Allreduce(&value, &result, 1, MPI_DOUBLE, mpi_op, MPI_COMM_WORLD), "MPI_Allreduce");
  return result;
#else
  return value;
#endif
}
}  // namespace

double sum_all(double value) { return reduce(value, Reduction::Sum); }
double max_all(double value) { return reduce(value, Reduction::Max); }
double min_all(double value) { return reduce(value, Reduction::Min); }

void sum_all([[maybe_unused]] std::vector<std::uint64_t>& values) {
#if RAYSIFT_HAVE_MPI
  if (size() == 1) return;
  check(MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD),
        "MPI_Allreduce");
#endif
}

Traffic traffic() { return state().traffic; }

void all_or_none(const std::function<void()>& step) {
  if (size() == 1) return step();
  Json failure = nullptr;
  try {
    step();
  } catch (const RankFailure& e) {  // an inner agreement already named the failing rank
    failure = {{"message", e.what()}, {"code", e.exit_code}, {"named", true}};
  } catch (const UsageError& e) {
    failure = {{"message", e.what()}, {"code", 2}, {"named", false}};
  } catch (const std::exception& e) {
    failure = {{"message", e.what()}, {"code", 1}, {"named", false}};
  }
  // Every rank learns the lowest failing rank's message, so that each can throw the same RankFailure.
  const int first = int(min_all(failure.is_null() ? double(size()) : double(rank())));
  if (first == size()) return;
  const Json chosen = broadcast_json(failure, first);
  std::string message = chosen["message"];
  if (first != 0 && !chosen["named"].get<bool>()) message = "rank " + std::to_string(first) + ": " + message;
  throw RankFailure(message, chosen["code"]);
}

}  // namespace raysift::mpi
