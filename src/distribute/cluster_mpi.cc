// The MPI side of distribute/cluster.h (built when CMake finds MPI).
#include <mpi.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "distribute/cluster.h"

namespace diverse {
namespace {

enum Tag : int { kSetup = 1, kReady = 2, kRefuse = 3, kTask = 4, kResult = 5, kFail = 6, kStop = 7, kBeat = 8 };

// A worker holding tasks sends `beat` whenever it has sent nothing for this long.
constexpr double kBeatSeconds = 0.5;

// Polling backoff: short sleeps while messages are frequent, longer ones when idle.
class Backoff {
 public:
  void reset() { wait_us_ = kMin; }
  void sleep() {
    std::this_thread::sleep_for(std::chrono::microseconds(wait_us_));
    wait_us_ = std::min(wait_us_ * 2, kMax);
  }
  int microseconds() const { return wait_us_; }

 private:
  static constexpr int kMin = 10;
  static constexpr int kMax = 200;
  int wait_us_ = kMin;
};

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) {
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    throw ClusterError(std::string("MPI: ") + what + ": " + std::string(text, static_cast<std::size_t>(length)));
  }
}

void send(const std::string& bytes, int to, int tag) {
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD),
        "send");
}

// Sends without blocking for longer than `timeout_seconds`: a plain MPI_Send to a rank
// that has stopped taking messages can wait forever (Open MPI's shared-memory transport
// waits for the receiver to hand back its buffers). Returns false if the send did not
// complete in that time; the message then stays in `abandoned`, which MPI may still read,
// and the caller gives the rank up.
bool send_within(const std::string& bytes, int to, int tag, double timeout_seconds,
                 std::vector<std::string>& abandoned) {
  MPI_Request request = MPI_REQUEST_NULL;
  check(MPI_Isend(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD, &request),
        "send");
  Backoff backoff;
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int done = 0;
    check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "send");
    if (done) return true;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_seconds) {
      abandoned.push_back(bytes);
      // The request is left to MPI: the process stops using MPI (no MPI_Finalize) once a
      // rank is lost.
      return false;
    }
    backoff.sleep();
  }
}

// Waits (polling) for a message from `from` (MPI_ANY_SOURCE allowed) and receives it.
// With `timeout_seconds` > 0, returns false if none came in that time.
bool receive(int from, int* tag, int* source, std::string* out, double timeout_seconds = 0) {
  Backoff backoff;
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int flag = 0;
    MPI_Status status;
    check(MPI_Iprobe(from, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "probe");
    if (flag) {
      int count = 0;
      MPI_Get_count(&status, MPI_BYTE, &count);
      std::string bytes(static_cast<std::size_t>(count), '\0');
      check(MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE),
            "receive");
      *tag = status.MPI_TAG;
      if (source) *source = status.MPI_SOURCE;
      *out = std::move(bytes);
      return true;
    }
    if (timeout_seconds > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_seconds)
      return false;
    backoff.sleep();
  }
}

// Non-blocking: receives a waiting message from `from`, if any.
bool try_receive(int from, std::string* bytes, int* tag, int* source) {
  int flag = 0;
  MPI_Status status;
  check(MPI_Iprobe(from, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "probe");
  if (!flag) return false;
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  bytes->assign(static_cast<std::size_t>(count), '\0');
  check(MPI_Recv(bytes->data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE),
        "receive");
  *tag = status.MPI_TAG;
  *source = status.MPI_SOURCE;
  return true;
}

struct Header {
  std::uint64_t batch = 0;
  std::uint64_t slot = 0;
  std::uint64_t compute_ns = 0;  // results: the worker's time in evaluate()
};

std::string with_header(Header h, const char* data, std::size_t size) {
  std::string out;
  out.reserve(sizeof(Header) + size);
  out.append(reinterpret_cast<const char*>(&h), sizeof(Header));
  out.append(data, size);
  return out;
}

Header header_of(const std::string& bytes) {
  if (bytes.size() < sizeof(Header)) throw std::logic_error("cluster: message without header");
  Header h;
  std::memcpy(&h, bytes.data(), sizeof(Header));
  return h;
}

// The stop message (set_stop_message), printed by the signal handler: two buffers so a
// signal never sees one half written.
constexpr std::size_t kStopCapacity = 4096;
char g_stop_text[2][kStopCapacity];
std::atomic<int> g_stop_length[2];
std::atomic<int> g_stop_current{-1};

extern "C" void on_stop_signal(int) {
  const int current = g_stop_current.load();
  if (current >= 0) {
    const int length = g_stop_length[current].load();
    ssize_t written = 0;
    while (written < length) {
      const ssize_t w = ::write(2, g_stop_text[current] + written, static_cast<std::size_t>(length - written));
      if (w <= 0) break;
      written += w;
    }
  }
  _exit(2);
}

int env_int(const char* name, int fallback) {
  const char* value = std::getenv(name);
  if (!value || !*value) return fallback;
  char* end = nullptr;
  const long v = std::strtol(value, &end, 10);
  return (*end == '\0' && v > 0 && v < 1000000) ? static_cast<int>(v) : fallback;
}

}  // namespace

struct Cluster::Impl {
  int rank = 0;
  int size = 1;
  int local_size = 1;
  std::string host;
  bool stopped = false;                 // rank 0: stop sent; worker: stop received
  std::vector<int> threads;             // rank 0: each worker's threads (index = rank)
  std::vector<std::string> hosts;       // rank 0: each worker's host
  std::uint64_t batches = 0;
  Traffic traffic;
  double rank_timeout = kDefaultRankTimeoutSeconds;  // rank 0: see set_rank_timeout
  bool lost = false;                    // rank 0: a worker stopped answering (no MPI_Finalize)
  std::vector<std::string> abandoned;   // rank 0: messages of sends given up (send_within)

  std::string who(int r) const {
    return "rank " + std::to_string(r) + " (" + (r < static_cast<int>(hosts.size()) && !hosts[static_cast<std::size_t>(r)].empty() ? hosts[static_cast<std::size_t>(r)] : std::string("?")) + ")";
  }

  // Rank 0 gives up on worker r: it has held work (or owed its setup answer) without a
  // word for longer than rank_timeout.
  ClusterError lost_rank(int r, const char* waiting_for) {
    lost = true;
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", rank_timeout);
    return ClusterError(who(r) + " has not answered for " + seconds + " s while " + waiting_for +
                        " (it was stopped, hangs, or its node or network is lost; --rank-timeout "
                        "sets how long to wait)");
  }
};

namespace {

// Rank 0's evaluator: workers and the local pool take slots from one counter.
class ClusterEvaluator : public BatchEvaluator {
 public:
  ClusterEvaluator(Cluster::Impl& impl, const DiversityProblem& problem, ThreadPool& pool,
                   Cluster::Decode decode)
      : impl_(impl), problem_(problem), pool_(pool), decode_(std::move(decode)) {}

  std::vector<std::shared_ptr<const Outcome>> evaluate(const std::vector<Eigen::VectorXd>& xs) override {
    const std::size_t n = xs.size();
    std::vector<std::shared_ptr<const Outcome>> outcomes(n);
    if (n == 0) return outcomes;
    const std::uint64_t batch = ++impl_.batches;
    std::atomic<std::size_t> next{0};
    std::atomic<bool> local_done{false};
    std::exception_ptr local_error;
    std::thread local([&] {
      try {
        pool_.parallel_for(static_cast<std::size_t>(pool_.size()), [&](std::size_t, int worker) {
          for (;;) {
            const std::size_t k = next.fetch_add(1);
            if (k >= n) break;
            outcomes[k] = problem_.evaluate(xs[k], worker);
          }
        });
      } catch (...) {
        local_error = std::current_exception();
        next.store(n);
      }
      local_done.store(true);
    });
    try {
      dispatch(xs, batch, next, local_done, outcomes);
    } catch (...) {
      next.store(n);
      local.join();
      throw;
    }
    local.join();
    if (local_error) std::rethrow_exception(local_error);
    return outcomes;
  }

 private:
  void dispatch(const std::vector<Eigen::VectorXd>& xs, std::uint64_t batch,
                std::atomic<std::size_t>& next, const std::atomic<bool>& local_done,
                std::vector<std::shared_ptr<const Outcome>>& outcomes) {
    const std::size_t n = xs.size();
    std::vector<int> held(static_cast<std::size_t>(impl_.size), 0);
    using Clock = std::chrono::steady_clock;
    std::vector<Clock::time_point> sent(n);
    // When each worker last said anything (or, if it was idle, got its first task).
    std::vector<Clock::time_point> heard(static_cast<std::size_t>(impl_.size), Clock::now());
    int in_flight = 0;
    Backoff backoff;
    std::string bytes;
    for (;;) {
      // Hand out: every worker up to its thread count.
      for (int w = 1; w < impl_.size; ++w) {
        while (held[static_cast<std::size_t>(w)] < impl_.threads[static_cast<std::size_t>(w)]) {
          const std::size_t k = next.fetch_add(1);
          if (k >= n) break;
          if (held[static_cast<std::size_t>(w)] == 0) heard[static_cast<std::size_t>(w)] = Clock::now();
          const std::string task = with_header(Header{batch, k, 0}, reinterpret_cast<const char*>(xs[k].data()),
                                               static_cast<std::size_t>(xs[k].size()) * sizeof(double));
          sent[k] = Clock::now();
          if (!send_within(task, w, kTask, impl_.rank_timeout, impl_.abandoned))
            throw impl_.lost_rank(w, "evaluating samples");
          impl_.traffic.tasks += 1;
          impl_.traffic.task_bytes += static_cast<long long>(task.size());
          ++held[static_cast<std::size_t>(w)];
          ++in_flight;
        }
      }
      if (in_flight == 0 && next.load() >= n) {
        // Only the local pool may still be running its last slots.
        while (!local_done.load()) std::this_thread::sleep_for(std::chrono::microseconds(50));
        return;
      }
      int tag = 0, source = 0;
      if (in_flight > 0 && try_receive(MPI_ANY_SOURCE, &bytes, &tag, &source)) {
        backoff.reset();
        heard[static_cast<std::size_t>(source)] = Clock::now();
        if (tag == kBeat) continue;
        const Header h = header_of(bytes);
        if (tag == kFail)
          throw ClusterError(impl_.who(source) + ": " + bytes.substr(sizeof(Header)));
        if (tag != kResult || h.batch != batch || h.slot >= n || outcomes[h.slot])
          throw std::logic_error("cluster: unexpected message from " + impl_.who(source));
        impl_.traffic.result_bytes += static_cast<long long>(bytes.size());
        impl_.traffic.round_trip_seconds += std::chrono::duration<double>(Clock::now() - sent[h.slot]).count();
        impl_.traffic.compute_seconds += static_cast<double>(h.compute_ns) * 1e-9;
        impl_.traffic.compute_ms.push_back(static_cast<double>(h.compute_ns) * 1e-6);
        try {
          outcomes[h.slot] = decode_(bytes.substr(sizeof(Header)));
        } catch (const std::invalid_argument& e) {
          throw ClusterError(impl_.who(source) + ": sent an outcome this build cannot read (" +
                             e.what() + "); every rank must run the same build of diverse");
        }
        --held[static_cast<std::size_t>(source)];
        --in_flight;
        continue;
      }
      if (in_flight > 0) {
        const auto now = Clock::now();
        for (int w = 1; w < impl_.size; ++w) {
          if (held[static_cast<std::size_t>(w)] > 0 &&
              std::chrono::duration<double>(now - heard[static_cast<std::size_t>(w)]).count() > impl_.rank_timeout)
            throw impl_.lost_rank(w, "evaluating samples");
        }
      }
      backoff.sleep();
    }
  }

  Cluster::Impl& impl_;
  const DiversityProblem& problem_;
  ThreadPool& pool_;
  Cluster::Decode decode_;
};

}  // namespace

bool cluster_support() { return true; }

Cluster::Cluster(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Cluster> Cluster::join() {
  if (env_int("OMPI_COMM_WORLD_SIZE", 1) <= 1) return nullptr;
  int provided = 0;
  check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "init");
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw UserError("MPI: this MPI library does not allow threads (MPI_THREAD_FUNNELED)");
  }
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  auto impl = std::make_unique<Impl>();
  MPI_Comm_rank(MPI_COMM_WORLD, &impl->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &impl->size);
  impl->local_size = env_int("OMPI_COMM_WORLD_LOCAL_SIZE", 1);
  char name[MPI_MAX_PROCESSOR_NAME];
  int length = 0;
  MPI_Get_processor_name(name, &length);
  impl->host.assign(name, static_cast<std::size_t>(length));
  if (impl->rank == 0) {
    impl->threads.assign(static_cast<std::size_t>(impl->size), 0);
    impl->hosts.assign(static_cast<std::size_t>(impl->size), std::string());
    impl->hosts[0] = impl->host;
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGTERM, &action, nullptr);
    sigaction(SIGINT, &action, nullptr);
  }
  return std::unique_ptr<Cluster>(new Cluster(std::move(impl)));
}

Cluster::~Cluster() {
  if (impl_->lost) {
    // MPI_Finalize waits for every rank, the lost one too: leave without it. Rank 0's
    // nonzero exit makes mpirun stop the other ranks.
    signal(SIGTERM, SIG_DFL);
    signal(SIGINT, SIG_DFL);
    return;
  }
  if (impl_->rank == 0 && !impl_->stopped) {
    for (int w = 1; w < impl_->size; ++w)
      MPI_Send(nullptr, 0, MPI_BYTE, w, kStop, MPI_COMM_WORLD);
    impl_->stopped = true;
  }
  if (impl_->rank == 0) {
    signal(SIGTERM, SIG_DFL);
    signal(SIGINT, SIG_DFL);
  }
  MPI_Finalize();
}

int Cluster::rank() const { return impl_->rank; }

void Cluster::set_rank_timeout(double seconds) {
  if (!(seconds >= kMinRankTimeoutSeconds))
    throw std::invalid_argument("Cluster::set_rank_timeout: expected seconds >= the minimum");
  impl_->rank_timeout = seconds;
}
int Cluster::size() const { return impl_->size; }

int Cluster::default_threads() const {
  return std::max(1, ThreadPool::hardware_threads() / std::max(1, impl_->local_size));
}

void Cluster::start_workers(const std::string& setup) {
  if (impl_->rank != 0) throw std::logic_error("Cluster::start_workers: rank 0 only");
  for (int w = 1; w < impl_->size; ++w) send(setup, w, kSetup);
  for (int answered = 1; answered < impl_->size; ++answered) {
    int tag = 0, source = 0;
    std::string reply;
    if (!receive(MPI_ANY_SOURCE, &tag, &source, &reply, impl_->rank_timeout)) {
      for (int w = 1; w < impl_->size; ++w)
        if (impl_->hosts[static_cast<std::size_t>(w)].empty()) throw impl_->lost_rank(w, "setting up");
    }
    if (tag == kRefuse) throw ClusterError(impl_->who(source) + ": " + reply);
    const auto space = reply.find(' ');
    if (tag != kReady || space == std::string::npos)
      throw std::logic_error("cluster: unexpected reply from rank " + std::to_string(source));
    impl_->threads[static_cast<std::size_t>(source)] = std::max(1, std::atoi(reply.substr(0, space).c_str()));
    impl_->hosts[static_cast<std::size_t>(source)] = reply.substr(space + 1);
  }
}

std::unique_ptr<BatchEvaluator> Cluster::evaluator(const DiversityProblem& problem, ThreadPool& pool,
                                                   Decode decode) {
  if (impl_->rank != 0) throw std::logic_error("Cluster::evaluator: rank 0 only");
  return std::make_unique<ClusterEvaluator>(*impl_, problem, pool, std::move(decode));
}

void Cluster::set_stop_message(const std::string& line) {
  const int next = g_stop_current.load() == 0 ? 1 : 0;
  const std::string text = line.substr(0, kStopCapacity - 1) + "\n";
  std::memcpy(g_stop_text[next], text.data(), text.size());
  g_stop_length[next].store(static_cast<int>(text.size()));
  g_stop_current.store(next);
}

Cluster::Traffic Cluster::traffic() const { return impl_->traffic; }

bool Cluster::receive_setup(std::string* setup) {
  int tag = 0;
  receive(0, &tag, nullptr, setup);
  if (tag == kStop) {
    impl_->stopped = true;
    return false;
  }
  if (tag != kSetup) throw std::logic_error("cluster: expected the setup from rank 0");
  return true;
}

void Cluster::refuse_setup(const std::string& reason) {
  send(reason, 0, kRefuse);
  int tag = 0;
  while (!impl_->stopped) {
    std::string ignored;
    receive(0, &tag, nullptr, &ignored);
    impl_->stopped = tag == kStop;
  }
}

void Cluster::serve(const DiversityProblem& problem, int threads, Encode encode) {
  send(std::to_string(threads) + " " + impl_->host, 0, kReady);
  struct Done {
    bool fail = false;
    std::string bytes;
  };
  std::mutex mutex;
  std::condition_variable work_cv, done_cv;
  std::deque<std::string> tasks;
  std::deque<Done> done;
  bool stop = false;
  const int dim = problem.dim();

  std::vector<std::thread> pool;
  for (int worker = 0; worker < threads; ++worker) {
    pool.emplace_back([&, worker] {
      for (;;) {
        std::string task;
        {
          std::unique_lock<std::mutex> lock(mutex);
          work_cv.wait(lock, [&] { return stop || !tasks.empty(); });
          if (tasks.empty()) return;
          task = std::move(tasks.front());
          tasks.pop_front();
        }
        const Header h = header_of(task);
        Done result;
        try {
          if (task.size() != sizeof(Header) + static_cast<std::size_t>(dim) * sizeof(double))
            throw std::logic_error("a task of the wrong dimension (rank 0 runs another problem)");
          Eigen::VectorXd x(dim);
          std::memcpy(x.data(), task.data() + sizeof(Header), static_cast<std::size_t>(dim) * sizeof(double));
          const auto start = std::chrono::steady_clock::now();
          const auto evaluated = problem.evaluate(x, worker);
          Header out = h;
          out.compute_ns = static_cast<std::uint64_t>(
              std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count());
          const std::string outcome = encode(*evaluated);
          result.bytes = with_header(out, outcome.data(), outcome.size());
        } catch (const std::exception& e) {
          const std::string reason = std::string("evaluation failed: ") + e.what();
          result.fail = true;
          result.bytes = with_header(h, reason.data(), reason.size());
        }
        {
          std::lock_guard<std::mutex> lock(mutex);
          done.push_back(std::move(result));
        }
        done_cv.notify_one();
      }
    });
  }

  Backoff backoff;
  std::string bytes;
  // Tasks received and not yet answered, and when this rank last sent rank 0 anything.
  int outstanding = 0;
  auto last_sent = std::chrono::steady_clock::now();
  try {
    while (!impl_->stopped) {
      std::deque<Done> ready;
      {
        std::unique_lock<std::mutex> lock(mutex);
        if (done.empty())
          done_cv.wait_for(lock, std::chrono::microseconds(backoff.microseconds()));
        ready.swap(done);
      }
      for (const Done& d : ready) send(d.bytes, 0, d.fail ? kFail : kResult);
      const auto now = std::chrono::steady_clock::now();
      outstanding -= static_cast<int>(ready.size());
      if (!ready.empty()) {
        last_sent = now;
      } else if (outstanding > 0 && std::chrono::duration<double>(now - last_sent).count() >= kBeatSeconds) {
        // Still evaluating: tell rank 0 this rank is alive (results may take long).
        const std::string beat = with_header(Header{}, "", 0);
        send(beat, 0, kBeat);
        last_sent = now;
      }
      int tag = 0, source = 0;
      bool any = !ready.empty();
      while (try_receive(0, &bytes, &tag, &source)) {
        any = true;
        if (tag == kStop) {
          impl_->stopped = true;
          break;
        }
        if (tag != kTask) throw std::logic_error("cluster: unexpected message from rank 0");
        ++outstanding;
        {
          std::lock_guard<std::mutex> lock(mutex);
          tasks.push_back(std::move(bytes));
        }
        work_cv.notify_one();
      }
      if (any) backoff.reset(); else backoff.sleep();
    }
  } catch (...) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
      tasks.clear();
    }
    work_cv.notify_all();
    for (auto& t : pool) t.join();
    throw;
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
    tasks.clear();
  }
  work_cv.notify_all();
  for (auto& t : pool) t.join();
}

}  // namespace diverse
