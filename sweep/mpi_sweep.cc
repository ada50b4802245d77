#include "sweep/mpi_sweep.h"

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace linesim::sweep {

namespace {

enum Tag : int { kReady = 1, kResult = 2, kRun = 3, kStop = 4 };

// A run's outcome as bytes: fixed fields, the metrics, then the error's
// texts, each after its length.
void PackText(std::vector<char>& buf, const std::string& text) {
  const std::int64_t n = static_cast<std::int64_t>(text.size());
  const char* p = reinterpret_cast<const char*>(&n);
  buf.insert(buf.end(), p, p + sizeof n);
  buf.insert(buf.end(), text.begin(), text.end());
}

std::string UnpackText(const std::vector<char>& buf, std::size_t& at) {
  std::int64_t n = 0;
  if (buf.size() < at + sizeof n) throw std::runtime_error("short MPI result");
  std::memcpy(&n, buf.data() + at, sizeof n);
  at += sizeof n;
  if (n < 0 || buf.size() - at < static_cast<std::size_t>(n)) {
    throw std::runtime_error("short MPI result");
  }
  std::string text(buf.data() + at, static_cast<std::size_t>(n));
  at += static_cast<std::size_t>(n);
  return text;
}

std::vector<char> Pack(const RunOutcome& o) {
  const cosim::RunError& e = o.failure;
  const std::int64_t head[7] = {o.id,
                                static_cast<std::int64_t>(o.seed),
                                static_cast<std::int64_t>(o.status),
                                static_cast<std::int64_t>(o.metrics.size()),
                                static_cast<std::int64_t>(e.phase),
                                e.time ? 1 : 0,
                                e.time.value_or(0)};
  std::vector<char> buf(sizeof head + sizeof(double) * (1 + o.metrics.size()));
  char* at = buf.data();
  std::memcpy(at, head, sizeof head);
  at += sizeof head;
  std::memcpy(at, &o.wall_s, sizeof(double));
  at += sizeof(double);
  if (!o.metrics.empty()) std::memcpy(at, o.metrics.data(), sizeof(double) * o.metrics.size());
  for (const std::string* text : {&o.error, &e.unit, &e.unit_type, &e.variable, &e.cause}) {
    PackText(buf, *text);
  }
  // The files the run read: their count, then path and digest of each.
  PackText(buf, std::to_string(o.inputs.size()));
  for (const auto& [path, digest] : o.inputs) {
    PackText(buf, path);
    PackText(buf, digest);
  }
  return buf;
}

RunOutcome Unpack(const std::vector<char>& buf) {
  RunOutcome o;
  std::int64_t head[7];
  if (buf.size() < sizeof head + sizeof(double)) throw std::runtime_error("short MPI result");
  const char* at = buf.data();
  std::memcpy(head, at, sizeof head);
  at += sizeof head;
  o.id = head[0];
  o.seed = static_cast<std::uint64_t>(head[1]);
  o.status = static_cast<RunStatus>(head[2]);
  const auto n = static_cast<std::size_t>(head[3]);
  std::memcpy(&o.wall_s, at, sizeof(double));
  at += sizeof(double);
  std::size_t pos = sizeof head + sizeof(double) * (1 + n);
  if (buf.size() < pos) throw std::runtime_error("short MPI result");
  o.metrics.resize(n);
  if (n) std::memcpy(o.metrics.data(), at, sizeof(double) * n);
  cosim::RunError& e = o.failure;
  e.phase = static_cast<cosim::RunPhase>(head[4]);
  if (head[5] != 0) e.time = head[6];
  for (std::string* text : {&o.error, &e.unit, &e.unit_type, &e.variable, &e.cause}) {
    *text = UnpackText(buf, pos);
  }
  const std::string count = UnpackText(buf, pos);
  char* end = nullptr;
  const unsigned long long files = std::strtoull(count.c_str(), &end, 10);
  if (count.empty() || *end != '\0' || files > buf.size())
    throw std::runtime_error("bad MPI result");
  for (unsigned long long i = 0; i < files; ++i) {
    std::string path = UnpackText(buf, pos);
    o.inputs[std::move(path)] = UnpackText(buf, pos);
  }
  e.message = o.error;
  return o;
}

void SendRun(std::int64_t id, int rank) {
  MPI_Send(&id, 1, MPI_INT64_T, rank, kRun, MPI_COMM_WORLD);
}

void SendStop(int rank) {
  const std::int64_t none = -1;
  MPI_Send(&none, 1, MPI_INT64_T, rank, kStop, MPI_COMM_WORLD);
}

}  // namespace

bool LaunchedByMpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"}) {
    if (std::getenv(name)) return true;
  }
  return false;
}

MpiSession::MpiSession(int* argc, char*** argv) {
  // Only the main thread talks MPI.
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

int MpiSession::ShareStatus(int status) const {
  int worst = status;
  MPI_Allreduce(&status, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return worst;
}

int MpiSession::LeaderStatus(int status) const {
  MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return status;
}

std::string MpiSession::LeaderText(const std::string& text) const {
  int size = static_cast<int>(text.size());
  MPI_Bcast(&size, 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string out = rank_ == 0 ? text : std::string(static_cast<std::size_t>(size), '\0');
  MPI_Bcast(out.data(), size, MPI_CHAR, 0, MPI_COMM_WORLD);
  return out;
}

void MpiSession::Abort(int status) const {
  MPI_Abort(MPI_COMM_WORLD, status);
  std::abort();  // MPI_Abort does not return
}

void DispatchRuns(const SweepSpec& spec, const std::vector<std::int64_t>& ids,
                  std::atomic<bool>& stop, const OnRunDone& on_done) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size == 1) {
    RunOnThreads(spec, ids, 1, stop, on_done);
    return;
  }
  std::size_t next = 0;
  int active = size - 1;  // workers not yet told to stop
  std::vector<char> buf;
  std::exception_ptr failure;
  while (active > 0) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status);
    if (!arrived) {
      // Polling politely: a blocking receive would spin a core that a
      // worker rank on the same machine needs. 1 ms is nothing next to a run.
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    int count = 0;
    MPI_Get_count(&status, MPI_CHAR, &count);
    buf.resize(static_cast<std::size_t>(count));
    MPI_Recv(buf.data(), count, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    if (status.MPI_TAG == kResult && !failure) {
      // Whatever goes wrong here, every worker is still answered (told to
      // stop), so that no rank is left waiting in a receive.
      try {
        const RunOutcome outcome = Unpack(buf);
        if (outcome.status == RunStatus::kInterrupted) {
          stop = true;
        } else {
          on_done(PlanRun(spec, outcome.id), outcome);
        }
      } catch (...) {
        failure = std::current_exception();
        stop = true;
      }
    }
    if (!stop.load() && next < ids.size()) {
      SendRun(ids[next++], status.MPI_SOURCE);
    } else {
      SendStop(status.MPI_SOURCE);
      --active;
    }
  }
  if (failure) std::rethrow_exception(failure);
}

void ServeRuns(const SweepSpec& spec, std::atomic<bool>& stop) {
  MPI_Send(nullptr, 0, MPI_CHAR, 0, kReady, MPI_COMM_WORLD);
  while (true) {
    MPI_Status status;
    std::int64_t id = 0;
    MPI_Recv(&id, 1, MPI_INT64_T, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &status);
    if (status.MPI_TAG == kStop) return;
    const RunOutcome outcome = ExecuteRun(spec, PlanRun(spec, id), &stop);
    std::vector<char> buf = Pack(outcome);
    MPI_Send(buf.data(), static_cast<int>(buf.size()), MPI_CHAR, 0, kResult, MPI_COMM_WORLD);
  }
}

}  // namespace linesim::sweep
