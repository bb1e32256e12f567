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
ServedDevice modbus(std::unique_ptr<Face> face, int port, int unit = 1,
                    UnitLink link = UnitLink::tcp_device) {
  auto server = std::make_unique<ModbusServer>(*face, unit);
  server->start_tcp(port, link);
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
ServedDevice generic(ModbusDeviceModel& model, int port, int unit = 1,
                     UnitLink link = UnitLink::tcp_device) {
  auto server = std::make_unique<ModbusServer>(model, unit);
  server->start_tcp(port, link);
  ServedDevice d;
  d.server = std::move(server);
  return d;
}

}  // namespace

ServedDevice serve_chamber(std::string_view name, ChamberSim& chamber, const WatlowPanel& panel,
                           int port, bool gateway) {
  // The registry names the dialects (and their old names); this table gives each its face.
  const std::string_view model = drivers::chamber_dialect(name).model;
  const int unit = panel.modbus_address;
  const UnitLink link = gateway ? UnitLink::tcp_gateway : UnitLink::tcp_device;
  if (model == "generic_plc") return generic(chamber, port, unit, link);
  if (model == "watlow_f4")
    return modbus(std::make_unique<F4Face>(chamber, panel, unit), port, unit, link);
  if (model == "watlow_f4t_map2")
    return modbus(std::make_unique<F4Face>(chamber, panel, unit, "watlow_f4t_map2"), port, unit,
                  link);
  if (model == "watlow_f4t")  // behind a gateway the unit is on its serial port: RTU registers
    return modbus(std::make_unique<F4tFace>(chamber, panel, unit, gateway), port, unit, link);
  if (model == "watlow_f4p")
    return modbus(std::make_unique<F4pFace>(chamber, panel, unit), port, unit, link);
  if (gateway)
    throw std::invalid_argument(fmt::format("no Modbus gateway in front of '{}'", model));
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

std::optional<double> dialect_rate_limit_dps(std::string_view name) {
  // docs/DEVICES.md, generic_plc: "A rate demand is bounded at +-500 deg/s by the station's own
  // specification". An ACUTROL's is the unit's own setting (:Limit:Rate), read at connect.
  constexpr double kGenericPlcRateDemandDps = 500.0;
  if (drivers::turntable_dialect(name).model == "generic_plc") return kGenericPlcRateDemandDps;
  return std::nullopt;
}

std::string device_toml(const char* section, std::string_view model, const std::string& endpoint,
                        const WatlowPanel* panel, bool gateway) {
  std::string out =
      fmt::format("[{}]\nmodel = \"{}\"\nendpoint = \"{}\"\n", section, model, endpoint);
  if (panel != nullptr && panel->run_event != 1 && drivers::chamber_dialect(model).event_outputs)
    out += fmt::format("run_event = {}\n", panel->run_event);
  if (panel != nullptr && panel->modbus_address != 1)
    out += fmt::format("unit_id = {}\n", panel->modbus_address);
  if (panel != nullptr && panel->float_words != drivers::modbus::WordOrder::cdab &&
      drivers::chamber_dialect(model).model == "watlow_f4t")
    out += "word_order = \"high_low\"\n";
  if (gateway) out += "gateway = true\n";
  return out;
}

}  // namespace station::sim
