#include "connection_gate.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <grpcpp/grpcpp.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace egress::navd {
namespace {

constexpr int kPollPeriodMs = 100;  // how soon Stop() is noticed
constexpr int kBacklog = 128;

std::uint64_t InodeOf(int fd) {
  struct stat st {};
  return fstat(fd, &st) == 0 ? std::uint64_t(st.st_ino) : 0;
}

}  // namespace

HostPort ParseListenAddress(const std::string& address) {
  const auto colon = address.rfind(':');
  if (colon == std::string::npos || colon + 1 == address.size()) {
    throw std::invalid_argument("listen address '" + address + "' has no port (host:port)");
  }
  HostPort out;
  out.host = address.substr(0, colon);
  if (out.host.size() >= 2 && out.host.front() == '[' && out.host.back() == ']')
    out.host = out.host.substr(1, out.host.size() - 2);
  const std::string port = address.substr(colon + 1);
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), out.port);
  if (ec != std::errc() || end != port.data() + port.size() || out.port < 0 || out.port > 65535) {
    throw std::invalid_argument("listen address '" + address + "': port '" + port +
                                "' is not a number in 0..65535");
  }
  if (out.host.empty()) throw std::invalid_argument("listen address '" + address + "' has no host");
  return out;
}

ConnectionGate::ConnectionGate(const std::string& address, int max_connections)
    : max_connections_(max_connections) {
  if (max_connections < 1) throw std::invalid_argument("max_connections must be >= 1");
  const HostPort hp = ParseListenAddress(address);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(hp.port);
  if (const int rc = getaddrinfo(hp.host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    throw std::runtime_error("cannot listen on '" + address + "': " + gai_strerror(rc));
  }
  std::string why = "no address";
  for (addrinfo* a = found; a != nullptr && listen_fd_ < 0; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd < 0) {
      why = std::strerror(errno);
      continue;
    }
    const int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 || listen(fd, kBacklog) != 0) {
      why = std::strerror(errno);
      close(fd);
      continue;
    }
    listen_fd_ = fd;
  }
  freeaddrinfo(found);
  if (listen_fd_ < 0) throw std::runtime_error("cannot listen on '" + address + "': " + why);
  sockaddr_storage bound{};
  socklen_t length = sizeof(bound);
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &length);
  port_ = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
  spare_fd_ = open("/dev/null", O_RDONLY | O_CLOEXEC);
}

ConnectionGate::~ConnectionGate() {
  Stop();
  if (spare_fd_ >= 0) close(spare_fd_);
}

void ConnectionGate::Start(grpc::experimental::ExternalConnectionAcceptor* acceptor) {
  thread_ = std::thread([this, acceptor] { Loop(acceptor); });
}

void ConnectionGate::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (listen_fd_ >= 0) {
    close(listen_fd_);
    listen_fd_ = -1;
  }
}

ConnectionGate::Counts ConnectionGate::counts() {
  std::lock_guard lock(mutex_);
  counts_.live = PruneClosed();
  return counts_;
}

int ConnectionGate::PruneClosed() {
  std::erase_if(handed_, [](const Handed& h) { return InodeOf(h.fd) != h.inode; });
  return int(handed_.size());
}

void ConnectionGate::Loop(grpc::experimental::ExternalConnectionAcceptor* acceptor) {
  while (!stop_) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (poll(&p, 1, kPollPeriodMs) <= 0) continue;
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) {
      if (errno == EMFILE || errno == ENFILE) {
        // Out of descriptors: take the waiting connection with the spare one and close it, so
        // it is refused now rather than left in the backlog (where poll would spin on it).
        std::lock_guard lock(mutex_);
        if (spare_fd_ >= 0) close(spare_fd_);
        const int refused = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
        if (refused >= 0) close(refused);
        spare_fd_ = open("/dev/null", O_RDONLY | O_CLOEXEC);
        ++counts_.refused;
      }
      continue;  // EAGAIN, ECONNABORTED, EINTR...: the listener lives on
    }
    {
      std::lock_guard lock(mutex_);
      if (PruneClosed() >= max_connections_) {
        close(fd);
        ++counts_.refused;
        continue;
      }
      handed_.push_back({fd, InodeOf(fd)});
      ++counts_.accepted;
    }
    const int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
    grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters params;
    params.listener_fd = listen_fd_;
    params.fd = fd;
    acceptor->HandleNewConnection(&params);
  }
}

}  // namespace egress::navd
