#include "workers.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <optional>

#include <fmt/format.h>

#include "commands.h"

namespace egress::apps {
namespace {

bool WriteAll(int fd, const std::string& text) {
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += std::size_t(n);
  }
  return true;
}

// The worker's side: item numbers in on `commands` (one per line), results out on `results`.
[[noreturn]] void WorkerMain(int commands, int results,
                             const std::function<nlohmann::json(std::size_t)>& run_one,
                             pid_t parent) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a killed batch leaves no orphan running trials
  if (::getppid() != parent) ::_exit(1);
  std::string buffer;
  char chunk[256];
  for (;;) {
    std::size_t newline;
    while ((newline = buffer.find('\n')) == std::string::npos) {
      const ssize_t n = ::read(commands, chunk, sizeof chunk);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) ::_exit(0);  // no more work
      buffer.append(chunk, std::size_t(n));
    }
    const std::size_t item = std::stoull(buffer.substr(0, newline));
    buffer.erase(0, newline + 1);
    nlohmann::json result;
    try {
      result = run_one(item);
    } catch (const std::exception& e) {
      result = {{"error", e.what()}};
    }
    if (!WriteAll(results, nlohmann::json{{"i", item}, {"r", result}}.dump() + "\n")) ::_exit(3);
  }
}

struct Worker {
  pid_t pid{-1};
  int commands{-1};  // parent writes item numbers
  int results{-1};   // parent reads result lines
  std::string buffer;
  std::optional<std::size_t> running;
};

}  // namespace

nlohmann::json CrashedResult(int wait_status) {
  nlohmann::json crashed;
  std::string why;
  if (WIFSIGNALED(wait_status)) {
    const int signal = WTERMSIG(wait_status);
    crashed["signal"] = signal;
    why = fmt::format("signal {} ({})", signal, ::strsignal(signal));
  } else {
    const int code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
    crashed["exit_code"] = code;
    why = fmt::format("exit code {}", code);
  }
  return {{"crashed", crashed}, {"error", "worker died: " + why}};
}

std::vector<nlohmann::json> RunInWorkers(std::size_t count,
                                         const std::function<nlohmann::json(std::size_t)>& run_one,
                                         const WorkerPoolOptions& options) {
  std::vector<nlohmann::json> results(count);
  std::deque<std::size_t> pending;
  for (std::size_t i = 0; i < count; ++i) {
    if (i >= options.skip.size() || !options.skip[i]) pending.push_back(i);
  }
  std::size_t done = count - pending.size();
  if (pending.empty()) return results;
  const int jobs = std::max(1, std::min<int>(options.jobs, int(pending.size())));
  // A worker that died is seen as EOF on its pipe; writing to it must not kill the parent.
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ignore, &previous);
  const pid_t parent = ::getpid();

  const auto spawn = [&]() -> Worker {
    int to_worker[2], from_worker[2];
    if (::pipe2(to_worker, O_CLOEXEC) != 0 || ::pipe2(from_worker, O_CLOEXEC) != 0)
      throw CommandFailed("cannot create a pipe for a worker");
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) throw CommandFailed("cannot fork a worker");
    if (pid == 0) {
      ::close(to_worker[1]);
      ::close(from_worker[0]);
      WorkerMain(to_worker[0], from_worker[1], run_one, parent);
    }
    ::close(to_worker[0]);
    ::close(from_worker[1]);
    Worker w;
    w.pid = pid;
    w.commands = to_worker[1];
    w.results = from_worker[0];
    return w;
  };
  // Hands the worker its next item, or closes its command pipe (it exits) when none is left.
  const auto feed = [&](Worker& w) {
    if (pending.empty()) {
      if (w.commands >= 0) ::close(w.commands);
      w.commands = -1;
      return;
    }
    w.running = pending.front();
    pending.pop_front();
    WriteAll(w.commands, fmt::format("{}\n", *w.running));  // a dead worker shows as EOF
  };

  const auto started = std::chrono::steady_clock::now();
  const auto draw = [&] {
    if (!options.progress) return;
    const double fraction = double(done) / double(count);
    const int filled = int(fraction * 40);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::fprintf(stderr, "\r  [%s%s] %zu/%zu %s  %.0f s",
                 std::string(std::size_t(filled), '#').c_str(),
                 std::string(std::size_t(40 - filled), ' ').c_str(), done, count,
                 options.what.c_str(), elapsed);
    std::fflush(stderr);
  };
  const auto record = [&](std::size_t i, const nlohmann::json& result) {
    if (i >= count || !results[i].is_null()) return;
    results[i] = result;
    ++done;
    if (options.on_result) options.on_result(i, result);
    draw();
  };

  std::vector<Worker> workers;
  try {
    for (int j = 0; j < jobs; ++j) {
      workers.push_back(spawn());
      feed(workers.back());
    }
    draw();
    while (!workers.empty()) {
      std::vector<pollfd> fds;
      for (const Worker& w : workers)
        fds.push_back({w.results, POLLIN, 0});
      if (::poll(fds.data(), fds.size(), -1) < 0) continue;
      for (std::size_t k = 0; k < workers.size(); ++k) {
        if (fds[k].revents == 0) continue;
        Worker& w = workers[k];
        char chunk[4096];
        const ssize_t n = ::read(w.results, chunk, sizeof chunk);
        if (n < 0 && errno == EINTR) continue;
        if (n > 0) {
          w.buffer.append(chunk, std::size_t(n));
          std::size_t newline;
          while ((newline = w.buffer.find('\n')) != std::string::npos) {
            const nlohmann::json line = nlohmann::json::parse(w.buffer.substr(0, newline));
            w.buffer.erase(0, newline + 1);
            record(line.at("i").get<std::size_t>(), line.at("r"));
            w.running.reset();
            feed(w);
          }
          continue;
        }
        // EOF: the worker is gone, done or dead.
        ::close(w.results);
        w.results = -1;
        if (w.commands >= 0) ::close(w.commands);
        w.commands = -1;
        int status = 0;
        while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
        }
        w.pid = -1;
        if (w.running) record(*w.running, CrashedResult(status));
        w.running.reset();
      }
      // Replace the dead, drop the finished.
      std::vector<Worker> alive;
      for (Worker& w : workers) {
        if (w.results >= 0) {
          alive.push_back(std::move(w));
        } else if (!pending.empty()) {
          alive.push_back(spawn());
          feed(alive.back());
        }
      }
      workers = std::move(alive);
    }
  } catch (...) {
    for (Worker& w : workers) {
      if (w.pid > 0) ::kill(w.pid, SIGKILL);
      if (w.pid > 0) ::waitpid(w.pid, nullptr, 0);
    }
    ::sigaction(SIGPIPE, &previous, nullptr);
    throw;
  }
  ::sigaction(SIGPIPE, &previous, nullptr);
  if (options.progress) std::fprintf(stderr, "\n");
  return results;
}

std::vector<nlohmann::json> RunInWorkers(std::size_t count, int jobs, bool progress,
                                         const std::function<nlohmann::json(std::size_t)>& run_one,
                                         const std::string& what) {
  WorkerPoolOptions options;
  options.jobs = jobs;
  options.progress = progress;
  options.what = what;
  return RunInWorkers(count, run_one, options);
}

}  // namespace egress::apps
