// Which face serves the simulated chamber and table for each dialect (the simulator's side of
// drivers/registry/dialects.cpp): one line per model.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/acutrol_face.hpp"
#include "sim_devices/faces/watlow_faces.hpp"
#include "sim_devices/servers/sim_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace station::sim {

/// A face and the server speaking it, started on 127.0.0.1:port (0: ephemeral).
struct ServedDevice {
  std::unique_ptr<void, void (*)(void*)> face{nullptr, [](void*) {}};
  std::unique_ptr<SimServer> server;
};

/// The chamber model served as `model` (a drivers/registry chamber model) at the panel's Modbus
/// address; `gateway`: a serial unit behind a TCP-to-RTU gateway (its RTU registers, exception
/// 0x0B for another unit id), else the unit's own TCP port. Throws std::invalid_argument for a
/// model without a simulator face, or a gateway in front of an ASCII unit.
ServedDevice serve_chamber(std::string_view model, ChamberSim& chamber, const WatlowPanel& panel,
                           int port, bool gateway = false);
/// The table model served as `model`; an ACUTROL frames its replies as `acutrol_framing` says.
ServedDevice serve_turntable(std::string_view model, TurntableSim& table, int port,
                             AclFraming acutrol_framing = AclFraming::bare);
/// A turntable dialect's own bound on a rate demand, deg/s, as its document gives it (empty: none
/// fixed). The simulator's reading of docs/DEVICES.md, not the driver's (drivers/registry's
/// `rate_limit_dps`): tests/drivers/test_sim_rate_limit.cpp holds the two readings equal.
std::optional<double> dialect_rate_limit_dps(std::string_view model);

/// The [chamber] / [turntable] table text a station config needs for a served model (its
/// run event, unit id, word order and gateway as the panel and the serving say).
std::string device_toml(const char* section, std::string_view model, const std::string& endpoint,
                        const WatlowPanel* panel, bool gateway = false);

}  // namespace station::sim
