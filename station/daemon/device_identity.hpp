// What a device endpoint names, independent of how it is spelled: the key a device lock is taken
// on, so two configurations that reach one chamber by different names cannot drive it at once.
#pragma once

#include <string>
#include <vector>

namespace station {

/// The canonical names of the device an endpoint reaches (one lock each):
/// - `tcp://HOST:PORT`: every numeric address HOST resolves to (getaddrinfo), with the port,
///   e.g. `tcp://localhost:502` -> {"tcp://127.0.0.1:502", "tcp://[::1]:502"}; an IPv4-mapped
///   IPv6 address is its IPv4 address;
/// - `rtu:DEV?...`: `rtu:` + the device path with every symlink resolved (line settings dropped:
///   one serial line is one device whatever the baud rate asked);
/// - `socketcan:IFACE`: the interface's kernel name (an altname resolves to it);
/// - `unix:PATH`: the socket path with symlinks resolved;
/// - `fd:N`: the inherited descriptor's inode (another process inheriting the same socket end
///   names the same device).
/// Names that cannot be resolved (a host not in DNS, a device not present) are kept as written
/// (lower-cased host), so the lock still excludes the same spelling.
std::vector<std::string> device_identities(const std::string& endpoint);

}  // namespace station
