#include "workers.h"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <fmt/format.h>

#include "commands.h"

namespace egress::apps {

std::vector<nlohmann::json> RunInWorkers(std::size_t count, int jobs, bool progress,
                                         const std::function<nlohmann::json(std::size_t)>& run_one,
                                         const std::string& what) {
  if (count == 0) return {};
  jobs = std::max(1, std::min<int>(jobs, int(count)));
  std::fflush(nullptr);
  struct Worker {
    pid_t pid;
    int fd;
    std::string buffer;
    bool open{true};
  };
  std::vector<Worker> workers;
  for (int j = 0; j < jobs; ++j) {
    int fds[2];
    if (::pipe(fds) != 0) throw CommandFailed("cannot create a pipe for a worker");
    const pid_t pid = ::fork();
    if (pid < 0) throw CommandFailed("cannot fork a worker");
    if (pid == 0) {
      ::close(fds[0]);
      for (std::size_t k = std::size_t(j); k < count; k += std::size_t(jobs)) {
        nlohmann::json result;
        try {
          result = run_one(k);
        } catch (const std::exception& e) {
          result = {{"error", e.what()}};
        }
        const std::string line = nlohmann::json{{"i", k}, {"r", result}}.dump() + "\n";
        std::size_t written = 0;
        while (written < line.size()) {
          const ssize_t n = ::write(fds[1], line.data() + written, line.size() - written);
          if (n <= 0) ::_exit(3);
          written += std::size_t(n);
        }
      }
      ::close(fds[1]);
      ::_exit(0);
    }
    ::close(fds[1]);
    workers.push_back({pid, fds[0], {}});
  }
  std::vector<nlohmann::json> results(count);
  std::size_t done = 0;
  const auto started = std::chrono::steady_clock::now();
  const auto draw = [&] {
    if (!progress) return;
    const double fraction = double(done) / double(count);
    const int filled = int(fraction * 40);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::fprintf(
        stderr, "\r  [%s%s] %zu/%zu %s  %.0f s", std::string(std::size_t(filled), '#').c_str(),
        std::string(std::size_t(40 - filled), ' ').c_str(), done, count, what.c_str(), elapsed);
    std::fflush(stderr);
  };
  draw();
  std::size_t open = workers.size();
  while (open > 0) {
    std::vector<pollfd> fds;
    for (const Worker& w : workers) {
      if (w.open) fds.push_back({w.fd, POLLIN, 0});
    }
    if (::poll(fds.data(), fds.size(), -1) < 0) continue;
    for (Worker& w : workers) {
      if (!w.open) continue;
      const auto it =
          std::find_if(fds.begin(), fds.end(), [&](const pollfd& p) { return p.fd == w.fd; });
      if (it == fds.end() || it->revents == 0) continue;
      char chunk[4096];
      const ssize_t n = ::read(w.fd, chunk, sizeof chunk);
      if (n <= 0) {
        ::close(w.fd);
        w.open = false;
        --open;
        continue;
      }
      w.buffer.append(chunk, std::size_t(n));
      std::size_t newline;
      while ((newline = w.buffer.find('\n')) != std::string::npos) {
        const nlohmann::json line = nlohmann::json::parse(w.buffer.substr(0, newline));
        w.buffer.erase(0, newline + 1);
        const std::size_t i = line.at("i").get<std::size_t>();
        if (i < count && results[i].is_null()) ++done;
        if (i < count) results[i] = line.at("r");
        draw();
      }
    }
  }
  for (const Worker& w : workers) {
    int status = 0;
    ::waitpid(w.pid, &status, 0);
  }
  if (progress) std::fprintf(stderr, "\n");
  if (done != count) {
    throw CommandFailed(fmt::format("{} of {} {} reported (a worker died)", done, count, what));
  }
  return results;
}

}  // namespace egress::apps
