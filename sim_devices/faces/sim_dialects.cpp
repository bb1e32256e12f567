// The simulator's dialect table.
#include "sim_devices/faces/sim_dialects.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "drivers/registry/dialects.hpp"
#include "sim_devices/faces/ascii_faces.hpp"
#include "sim_devices/servers/line_server.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace station::sim {
namespace {

template <typename Face>
ServedDevice modbus(std::unique_ptr<Face> face, int port) {
  auto server = std::make_unique<ModbusServer>(*face, 1);
  server->start_tcp(port);
  ServedDevice d;
  d.face = {face.release(), [](void* p) { delete static_cast<Face*>(p); }};
  d.server = std::move(server);
  return d;
}

template <typename Face>
ServedDevice lines(std::unique_ptr<Face> face, int port) {
  auto server = std::make_unique<LineServer>(*face);
  server->start_tcp(port);
  ServedDevice d;
  d.face = {face.release(), [](void* p) { delete static_cast<Face*>(p); }};
  d.server = std::move(server);
  return d;
}

/// A model that is its own Modbus face (the station's generic PLC layout).
ServedDevice generic(ModbusDeviceModel& model, int port) {
  auto server = std::make_unique<ModbusServer>(model, 1);
  server->start_tcp(port);
  ServedDevice d;
  d.server = std::move(server);
  return d;
}

}  // namespace

ServedDevice serve_chamber(std::string_view name, ChamberSim& chamber, const WatlowPanel& panel,
                           int port) {
  // The registry names the dialects (and their old names); this table gives each its face.
  const std::string_view model = drivers::chamber_dialect(name).model;
  if (model == "generic_plc") return generic(chamber, port);
  if (model == "watlow_f4") return modbus(std::make_unique<F4Face>(chamber, panel), port);
  if (model == "watlow_f4t_map2")
    return modbus(std::make_unique<F4Face>(chamber, panel, 1, "watlow_f4t_map2"), port);
  if (model == "watlow_f4t") return modbus(std::make_unique<F4tFace>(chamber, panel), port);
  if (model == "watlow_f4p") return modbus(std::make_unique<F4pFace>(chamber, panel), port);
  if (model == "espec_p300") return lines(std::make_unique<P300Face>(chamber, 1), port);
  throw std::invalid_argument(
      fmt::format("no simulated chamber '{}' (known: {})", model, drivers::chamber_models()));
}

ServedDevice serve_turntable(std::string_view name, TurntableSim& table, int port,
                             AclFraming acutrol_framing) {
  const std::string_view model = drivers::turntable_dialect(name).model;
  if (model == "generic_plc") return generic(table, port);
  if (model == "acutrol3000")
    return lines(std::make_unique<AcutrolFace>(table, 1000.0, acutrol_framing), port);
  throw std::invalid_argument(
      fmt::format("no simulated turntable '{}' (known: {})", model, drivers::turntable_models()));
}

std::string device_toml(const char* section, std::string_view model, const std::string& endpoint,
                        const WatlowPanel* panel) {
  std::string out =
      fmt::format("[{}]\nmodel = \"{}\"\nendpoint = \"{}\"\n", section, model, endpoint);
  if (panel != nullptr && panel->run_event != 1 && drivers::chamber_dialect(model).event_outputs)
    out += fmt::format("run_event = {}\n", panel->run_event);
  return out;
}

}  // namespace station::sim
