#pragma once
// A DDS domain of its own for a test: ctest runs tests in parallel, and two tests on one domain
// hear each other's robots. A domain is claimed by creating a lock file exclusively (its owner's
// pid inside; a lock whose owner is gone is taken over) and released when the claim ends.

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace egress::testing {

class DdsDomain {
 public:
  DdsDomain() {
    for (int domain = 1; domain <= 232; ++domain) {
      const std::filesystem::path lock = Lock(domain);
      int fd = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
      if (fd < 0) {
        // Taken: by a live process, or left by one that died (then taken over).
        std::ifstream in(lock);
        int owner = 0;
        if (!(in >> owner) || owner <= 0 || ::kill(owner, 0) == 0) continue;
        std::filesystem::remove(lock);
        fd = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
        if (fd < 0) continue;
      }
      const std::string pid = std::to_string(::getpid());
      if (::write(fd, pid.data(), pid.size()) != ssize_t(pid.size())) {
        ::close(fd);
        std::filesystem::remove(lock);
        continue;
      }
      ::close(fd);
      domain_ = domain;
      return;
    }
    throw std::runtime_error("no free DDS domain (all 232 claimed)");
  }
  ~DdsDomain() { std::filesystem::remove(Lock(domain_)); }
  DdsDomain(const DdsDomain&) = delete;
  DdsDomain& operator=(const DdsDomain&) = delete;
  int id() const { return domain_; }
  std::string str() const { return std::to_string(domain_); }

 private:
  static std::filesystem::path Lock(int domain) {
    return std::filesystem::temp_directory_path() /
           ("egress_dds_domain_" + std::to_string(domain) + ".lock");
  }
  int domain_{0};
};

}  // namespace egress::testing
