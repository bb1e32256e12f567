// The Watlow tables, row by row as the documents give them (see the header for the sources).
#include "sim_devices/sources/watlow_sources.hpp"

#include <cmath>

namespace station::sim::sources {
namespace mb = drivers::modbus;

namespace {
constexpr auto I16 = mb::PointType::int16;
constexpr auto U16 = mb::PointType::uint16;
constexpr auto F32 = mb::PointType::float32;
constexpr auto ABCD = mb::WordOrder::abcd;
constexpr auto CDAB = mb::WordOrder::cdab;  // CCL modbus.py read_holding_float:157-173
constexpr bool RO = false, RW = true;

std::uint16_t u16(int v) {
  return static_cast<std::uint16_t>(v);
}
}  // namespace

mb::RegisterMap register_map(const std::string& device, int unit_id,
                             const std::vector<SourcePoint>& rows) {
  std::vector<mb::Point> points;
  for (const auto& r : rows)
    points.push_back(mb::Point{r.name, r.address, r.type, 1.0, r.order, mb::FunctionCode::holding,
                               unit_id, false, r.writable ? mb::Access::rw : mb::Access::ro,
                               r.nan_on_input_error});
  return mb::RegisterMap(device, std::move(points));
}

// deg F = deg C x 9/5 + 32.
double watlow_unit(double c, bool fahrenheit) {
  return fahrenheit ? c * 9.0 / 5.0 + 32.0 : c;
}
double watlow_c(double unit, bool fahrenheit) {
  return fahrenheit ? (unit - 32.0) * 5.0 / 9.0 : unit;
}
double watlow_c_delta(double d, bool fahrenheit) {
  return fahrenheit ? d * 5.0 / 9.0 : d;
}

double watlow_raw(double c, int decimals, bool fahrenheit) {
  const double r = std::nearbyint(watlow_unit(c, fahrenheit) * std::pow(10.0, decimals));
  if (!(r >= -32768 && r <= 32767)) return c > 0 ? 32767 : -32768;  // over range (NaN: under)
  return r;
}

double watlow_c_of_raw(std::int16_t raw, int decimals, bool fahrenheit) {
  return watlow_c(raw * std::pow(10.0, -decimals), fahrenheit);
}

namespace {
// The humidity event output of a Watlow F4 map (2000 + 10 (n - 1)), unless it is the run event.
void add_f4_humidity_event(std::vector<SourcePoint>& rows, int run_event, int humidity_event) {
  if (humidity_event < 1 || humidity_event == run_event) return;
  rows.push_back({f4::kHumidityEvent, u16(2000 + 10 * (humidity_event - 1)), U16, ABCD, RW,
                  "TE p. 51: event 2 is humidity in humidity models; CCL get_event:533"});
}
}  // namespace

std::vector<SourcePoint> f4::points(int run_event, int humidity_event) {
  std::vector<SourcePoint> rows{
      {kAir, 100, I16, ABCD, RO, "CCL watlowf4.py get_loop_pv:349"},
      {kAirError, 101, U16, ABCD, RO, "F4P p. 9.6"},
      {kProduct, 104, I16, ABCD, RO, "CCL get_loop_pv:349 (loop 2)"},
      {kProductError, 105, U16, ABCD, RO, "F4P p. 9.6 pattern (input 2): an assumption"},
      {kStatus, 200, U16, ABCD, RO, "CCL get_status:545"},
      {kSetpoint, 300, I16, ABCD, RW, "CCL get_loop_sp:329, set_loop_sp:342"},
      {kSetpointLow, 602, I16, ABCD, RO, "CCL get_loop_range:354"},
      {kSetpointHigh, 603, I16, ABCD, RO, "CCL get_loop_range:354"},
      {kDecimals, 606, U16, ABCD, RO, "CCL __get_scalar:100"},
      {kDecimals2, 616, U16, ABCD, RO, "CCL __get_scalar:100"},
      {kUnits, 901, U16, ABCD, RO, "CCL get_loop_units:396"},
      {kRunEvent, u16(2000 + 10 * (run_event - 1)), U16, ABCD, RW,
       "CCL get_event:533 (2000 + 10 (n - 1))"},
      {kInput1Units, 608, U16, ABCD, RO, "CCL get_loop_units:394 (0 temp, 1 %RH, 2 PSI, 3 none)"},
      {kInput2Units, 618, U16, ABCD, RO, "CCL get_loop_units:394"},
  };
  add_f4_humidity_event(rows, run_event, humidity_event);
  return rows;
}

std::vector<SourcePoint> f4t_map2::points(int run_event, int humidity_event) {
  namespace f4 = sources::f4;
  std::vector<SourcePoint> rows{
      {f4::kAir, 100, I16, ABCD, RO, "TE p. 47, TE101H p. 61: actual chamber temperature"},
      {f4::kAirError, 101, U16, ABCD, RO, "TE101H p. 61: temperature input error, 0 none, 1"},
      {f4::kProduct, 104, I16, ABCD, RO, "TE p. 47, TE101H p. 61: actual chamber HUMIDITY"},
      {f4::kProductError, 105, U16, ABCD, RO, "TE101H p. 61: humidity input error"},
      {f4::kSetpoint, 300, I16, ABCD, RW, "TE p. 47, TE101H p. 61"},
      {f4::kDecimals, 606, U16, ABCD, RO, "TE101H p. 61: temperature input precision"},
      {f4::kDecimals2, 616, U16, ABCD, RO, "TE101H p. 61: humidity input precision"},
      {f4::kUnits, 901, U16, ABCD, RO, "TE101H p. 61: C (1), F (0)"},
      {f4::kRunEvent, u16(2000 + 10 * (run_event - 1)), U16, ABCD, RW,
       "TE p. 47: events 1-7 at 2000 + 10 (n - 1), off 0, on 1"},
  };
  add_f4_humidity_event(rows, run_event, humidity_event);
  return rows;
}

std::string f4t::part_number_point(int i) {
  return "part_number_" + std::to_string(i);
}

std::vector<SourcePoint> f4t::points(int run_event, bool rtu, int loop, int humidity_event) {
  // Loop n's registers are loop 1's + 160 (n - 1) (CCL get_loop_pv:243, get_loop_sp:234 ...).
  const int o = 160 * (loop - 1);
  std::vector<SourcePoint> rows{
      // NaN on an input error: no source gives the value (A); Watlow F4T Setup & Operations
      // p. 83: a signal in error "cannot be relied on" (Open, Shorted, ... not None).
      {kAir, u16(2820 + o), F32, CDAB, RO, "CCL watlowf4t.py get_loop_pv:243", true},
      {kProduct, u16(2980 + o), F32, CDAB, RO, "CCL get_loop_pv:243 (the next loop)", true},
      {kSetpoint, u16(2782 + o), F32, CDAB, RW, "CCL get_loop_sp:234, set_loop_sp:241"},
      {kWorkingSetpoint, u16(2810 + o), F32, CDAB, RO, "CCL get_loop_sp:235"},
      {kSetpointLow, u16(2774 + o), F32, CDAB, RO, "CCL get_loop_range:256"},
      {kSetpointHigh, u16(2776 + o), F32, CDAB, RO, "CCL get_loop_range:256"},
      {kLoopMode, u16(2814 + o), U16, ABCD, RO, "CCL get_loop_en:264"},
      {kRampAction, u16(2794 + o), U16, ABCD, RW, "TE p. 46, 52"},
      {kRampScale, u16(2796 + o), U16, ABCD, RW, "TE p. 46, 52"},
      {kRampRate, u16(2798 + o), F32, CDAB, RW, "TE p. 46, 52"},
      {kProfileState, 16568, U16, ABCD, RO, "CCL get_status:528"},
      {kAlarm1, 1356, U16, ABCD, RO, "CCL get_alarm_status:552"},
      {kRunEvent, u16(kEvents[run_event - 1]), U16, ABCD, RW, "CCL get_event:499"},
      {kUnits, u16(rtu ? 14080 : 6730), U16, ABCD, RO, "CCL __profile_units:1003-1006"},
      {kLoop1Kind, u16(16536 + 2 * (loop - 1)), U16, ABCD, RO, "CCL __profile_units:997"},
      {kLoop2Kind, u16(16536 + 2 * loop), U16, ABCD, RO, "CCL __profile_units:997 (next loop)"},
  };
  if (humidity_event >= 1 && humidity_event != run_event)
    rows.push_back({kHumidityEvent, u16(kEvents[humidity_event - 1]), U16, ABCD, RW,
                    "TE p. 51: event 2 (16596) is humidity in humidity models"});
  for (int i = 0; i < kPartNumberRegisters; ++i)
    rows.push_back({part_number_point(i), u16(16 + i), U16, ABCD, RO,
                    "CCL process_controller:861 (one character per register)"});
  return rows;
}

std::vector<SourcePoint> f4p::points() {
  return {
      {kModel, 0, U16, ABCD, RO, "F4P p. 6.27"},
      {kAir, 100, I16, ABCD, RO, "F4P p. 9.6"},
      {kAirError, 101, U16, ABCD, RO, "F4P p. 9.6"},
      {kAlarm1, 102, U16, ABCD, RO, "F4P p. 9.2"},
      {kOperation, 200, U16, ABCD, RW, "F4P p. 9.2"},
      {kControlSetpoint, 298, I16, ABCD, RO, "F4P p. 9.4"},
      {kSetpoint, 300, I16, ABCD, RW, "F4P p. 9.9"},
      {kSetpointLow, 602, I16, ABCD, RO, "F4P p. 6.13"},
      {kSetpointHigh, 603, I16, ABCD, RO, "F4P p. 6.13"},
      {kDecimals, 606, U16, ABCD, RO, "F4P p. 6.13"},
      {kUnits, 901, U16, ABCD, RO, "F4P p. 6.11"},
      {kRampMode, 1100, U16, ABCD, RW, "F4P p. 6.7"},
      {kRampRate, 1101, I16, ABCD, RW, "F4P p. 6.8"},
      {kRampScale, 1102, U16, ABCD, RW, "F4P p. 6.8"},
  };
}

}  // namespace station::sim::sources
