// Fuzz target: the ASCII dialects' reply parsers (ESPEC P300 p300_wire, ACUTROL3000
// acutrol_wire: replies, status byte, a frame's error code; the shared number_field) and the
// simulator faces that read command lines (the ACUTROL's ACL parser, bare and framed replies).
// Input: one reply or request line as a device or station could send it.
// Properties: no crash or UB; a parsed number is finite; a parsed TEMP? reply's fields are
// finite; a face answers any line with a bounded reply and never throws.
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "drivers/ascii/number_field.hpp"
#include "drivers/chamber/espec_p300/p300_wire.hpp"
#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "fuzz_check.hpp"
#include "sim_devices/faces/acutrol_face.hpp"
#include "sim_devices/faces/ascii_faces.hpp"

namespace p3 = station::drivers::espec_p300;
namespace ac = station::drivers::acutrol3000;
using station::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  if (auto v = station::drivers::ascii::number_field(line)) check(std::isfinite(*v), "number");
  if (auto t = p3::parse_temp(line))
    check(std::isfinite(t->pv_c) && std::isfinite(t->sp_c) && std::isfinite(t->high_c) &&
              std::isfinite(t->low_c),
          "TEMP? fields finite");
  if (auto m = p3::parse_mon(line)) check(m->alarms >= 0, "MON? alarm count");
  (void)p3::parse_alarm(line);
  (void)p3::parse_product(line);
  (void)p3::parse_mode(line);
  (void)p3::is_error(line);
  if (auto pr = ac::parse_position_rate(line))
    check(std::isfinite(pr->first) && std::isfinite(pr->second), "position;rate finite");
  (void)ac::parse_mode(line);
  (void)ac::parse_interlock(line);
  if (auto b = ac::parse_status_byte(line)) check(*b <= 255, "status byte");
  if (line.size() >= 8) (void)ac::frame_error_code(line);
  check(ac::wrap_deg(static_cast<double>(size) * 37.5 - 1000.0) < 360.0, "wrap");
  static station::sim::ChamberSim chamber{station::drivers::chamber_map::generic_plc(1)};
  static station::sim::TurntableSim table{station::drivers::turntable_map::generic_plc(1)};
  static station::sim::P300Face p300(chamber, 1);
  static station::sim::AcutrolFace acutrol(table, 100.0);
  static station::sim::AcutrolFace framed(table, 100.0, station::sim::AclFraming::header);
  for (station::sim::LineDevice* face : {static_cast<station::sim::LineDevice*>(&p300),
                                         static_cast<station::sim::LineDevice*>(&acutrol),
                                         static_cast<station::sim::LineDevice*>(&framed)}) {
    if (auto reply = face->handle(line))
      check(face->encode(*reply).size() < 4096, "face reply bounded");
  }
  return 0;
}
