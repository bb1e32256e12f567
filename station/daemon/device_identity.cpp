// Device endpoints resolved to what they reach (device locks).
#include "station/daemon/device_identity.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <net/if.h>
#include <netdb.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>

#include "drivers/can/can_transport.hpp"
#include "drivers/modbus/endpoint.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

/// The path with every symlink resolved, or the absolute lexical path when it does not exist.
std::string resolved_path(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::canonical(path, ec);
  if (!ec) return p.string();
  return fs::absolute(path, ec).lexically_normal().string();
}

std::string numeric_address(const sockaddr* sa) {
  char text[INET6_ADDRSTRLEN] = {};
  if (sa->sa_family == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(sa)->sin_addr, text, sizeof text);
    return text;
  }
  const auto* in6 = &reinterpret_cast<const sockaddr_in6*>(sa)->sin6_addr;
  if (IN6_IS_ADDR_V4MAPPED(in6)) {
    inet_ntop(AF_INET, &in6->s6_addr[12], text, sizeof text);
    return text;
  }
  inet_ntop(AF_INET6, in6, text, sizeof text);
  return fmt::format("[{}]", text);
}

std::vector<std::string> tcp_identities(std::string host, int port) {
  std::transform(host.begin(), host.end(), host.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (host.size() > 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  std::vector<std::string> out;
  if (getaddrinfo(host.c_str(), nullptr, &hints, &found) == 0) {
    const std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> hold(found, freeaddrinfo);
    for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
      if (a->ai_family != AF_INET && a->ai_family != AF_INET6) continue;
      out.push_back(fmt::format("tcp://{}:{}", numeric_address(a->ai_addr), port));
    }
  }
  if (out.empty()) out.push_back(fmt::format("tcp://{}:{}", host, port));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<std::string> can_identities(const std::string& endpoint) {
  namespace can = drivers::can;
  const can::CanSpec spec = can::parse_can_spec(endpoint);
  switch (spec.kind) {
    case can::CanSpecKind::socketcan: {
      char name[IF_NAMESIZE] = {};
      const unsigned index = if_nametoindex(spec.target.c_str());
      if (index != 0 && if_indextoname(index, name) != nullptr)
        return {fmt::format("socketcan:{}", name)};
      return {"socketcan:" + spec.target};
    }
    case can::CanSpecKind::unix_seqpacket:
      return {"unix:" + resolved_path(spec.target)};
    case can::CanSpecKind::inherited_fd: {
      struct stat st {};
      if (::fstat(spec.fd, &st) == 0)
        return {fmt::format("fd-inode:{}:{}", static_cast<unsigned long long>(st.st_dev),
                            static_cast<unsigned long long>(st.st_ino))};
      return {endpoint};
    }
  }
  return {endpoint};
}

}  // namespace

std::vector<std::string> device_identities(const std::string& endpoint) {
  if (endpoint.starts_with("tcp://") || endpoint.starts_with("rtu:")) {
    const auto ep = drivers::modbus::parse_endpoint(endpoint);
    if (const auto* t = std::get_if<drivers::modbus::TcpEndpoint>(&ep))
      return tcp_identities(t->host, t->port);
    return {"rtu:" + resolved_path(std::get<drivers::modbus::RtuEndpoint>(ep).device)};
  }
  return can_identities(endpoint);
}

}  // namespace station
