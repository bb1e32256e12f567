// Turntable register map (wire definition shared by ModbusTurntable and TurntableSim).
//
// The station's own map, "generic_plc", for a table whose servo drive is fronted by a PLC or a
// Modbus TCP gateway programmed for the station. NOT a table maker's map (rate tables such as the
// ACUTROL3000 speak their own command languages: drivers/turntable/acutrol3000/); documented in
// docs/DEVICES.md as the station's definition. Unit 1, 0-based addresses:
//   holding (fc 3/6/16, rw)                     input (fc 4, ro)
//     0     mode demand: 0 off, 1 position, 2 rate  100-101 angle, float32 ABCD, deg [0,360)
//     2-3   position demand, float32 ABCD, deg       102-103 rate, float32 ABCD, deg/s
//     4-5   rate demand, float32 ABCD, deg/s         104 status bits: bit0 in position,
//     6     lock: 1 engaged, 0 released                    bit1 at rate, bit2 fault,
//     7     stop: write 1 for a controlled stop              bit3 interlock open
//                                                   105 mode actual (0/1/2)
#pragma once

#include <stdexcept>
#include <string>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::turntable_map {

using modbus::Access;
using modbus::FunctionCode;
using modbus::Point;
using modbus::PointType;
using modbus::RegisterMap;
using modbus::WordOrder;

/// Point names.
inline constexpr const char* kModeDemand = "mode_demand";
inline constexpr const char* kPositionDemand = "position_demand_deg";
inline constexpr const char* kRateDemand = "rate_demand_dps";
inline constexpr const char* kLock = "lock";
inline constexpr const char* kStop = "stop";
inline constexpr const char* kAngle = "angle_deg";
inline constexpr const char* kRate = "rate_dps";
inline constexpr const char* kStatus = "status";
inline constexpr const char* kModeActual = "mode_actual";

/// Status-register bit positions.
enum StatusBit : unsigned {
  kInPosition = 1u << 0,
  kAtRate = 1u << 1,
  kFault = 1u << 2,
  kInterlockOpen = 1u << 3
};

/// The generic PLC turntable map (see file comment).
inline RegisterMap generic_plc(int unit_id = 1) {
  auto p = [unit_id](const char* n, std::uint16_t a, PointType t, FunctionCode fc, Access acc) {
    return Point{n, a, t, 1.0, WordOrder::abcd, fc, unit_id, false, acc};
  };
  constexpr auto H = FunctionCode::holding;
  constexpr auto I = FunctionCode::input;
  constexpr auto F = PointType::float32;
  constexpr auto U = PointType::uint16;
  return RegisterMap("generic_plc",
                     {p(kModeDemand, 0, U, H, Access::rw), p(kPositionDemand, 2, F, H, Access::rw),
                      p(kRateDemand, 4, F, H, Access::rw), p(kLock, 6, U, H, Access::rw),
                      p(kStop, 7, U, H, Access::rw), p(kAngle, 100, F, I, Access::ro),
                      p(kRate, 102, F, I, Access::ro), p(kStatus, 104, U, I, Access::ro),
                      p(kModeActual, 105, U, I, Access::ro)});
}

}  // namespace station::drivers::turntable_map
