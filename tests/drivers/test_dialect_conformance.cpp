// Issue 20: each dialect's wire definition (what the driver uses) against the table transcribed
// by hand from the maker's document or public client library (sim_devices/sources/), which the
// simulator speaks from. The driver's map and the simulator's are two readings of one document:
// a wrong address, type, word order or code is a failing test here, and a driver-simulator run
// that disagrees fails too. docs/DEVICES.md cites the same sources per point.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "drivers/chamber/espec_p300/p300_wire.hpp"
#include "drivers/chamber/scaled_temperature.hpp"
#include "drivers/chamber/watlow_f4/f4_map.hpp"
#include "drivers/chamber/watlow_f4p/f4p_map.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"
#include "sim_devices/faces/acl_parser.hpp"
#include "sim_devices/sources/acutrol_sources.hpp"
#include "sim_devices/sources/espec_p300_sources.hpp"
#include "sim_devices/sources/watlow_sources.hpp"

namespace {

namespace mb = station::drivers::modbus;
namespace src = station::sim::sources;
using mb::PointType;
using mb::WordOrder;

/// Every source row is in the driver's map as the source gives it, and the driver's map has no
/// point the sources do not give.
void check(const mb::RegisterMap& map, const std::vector<src::SourcePoint>& rows) {
  std::set<std::string> named;
  for (const auto& r : rows) {
    SCOPED_TRACE(r.name + " (" + r.source + ")");
    named.insert(r.name);
    const auto* p = map.find(r.name);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(p->pdu_address(), r.address);
    EXPECT_EQ(p->type, r.type);
    if (r.type == PointType::float32) {
      EXPECT_EQ(p->order, r.order);
    }
    EXPECT_EQ(p->function, mb::FunctionCode::holding);  // all three use holding registers only
    EXPECT_EQ(p->access == mb::Access::rw, r.writable);
    EXPECT_EQ(p->scale, 1.0);  // raw on the wire; decimals/units are read from the unit
    // Which points read NaN on an input failure (a reading) and which never may (an error).
    EXPECT_EQ(p->nan_on_input_error, r.nan_on_input_error);
  }
  for (const auto& [name, p] : map.points())
    EXPECT_EQ(named.count(name), 1u)
        << map.device() << ": the driver's point '" << name << "' is in no source row";
}

// ESPEC ChamberConnectLibrary @1d2deb8 watlowf4.py (CCL) and the Watlow F4P manual Rev E (F4P).
TEST(Conformance, WatlowF4MatchesChamberConnectLibrary) {
  namespace d = station::drivers::watlow_f4;
  for (int event = 1; event <= 8; ++event) {
    SCOPED_TRACE("run event " + std::to_string(event));
    check(d::map(1, event), src::f4::points(event));
  }
  for (const auto& r : src::f4::points(3)) {
    if (r.name == src::f4::kRunEvent) {
      EXPECT_EQ(r.address, 2020);  // CCL get_event:533, n = 3
    }
  }
  for (int hum = 0; hum <= 8; ++hum) {
    SCOPED_TRACE("humidity event " + std::to_string(hum));
    check(d::map(1, 1, "watlow_f4", hum), src::f4::points(1, hum));
  }
  EXPECT_EQ(d::kTemperature, src::f4::kInputTemperature);  // CCL get_loop_units:394
  EXPECT_EQ(d::kHumidity, src::f4::kInputHumidity);
  EXPECT_EQ(d::kPressure, src::f4::kInputPressure);
  EXPECT_EQ(d::kDefaultHumidityEvent, src::f4::kHumidityEventNumber);  // TestEquity p. 51
  EXPECT_EQ(d::kEventOn, src::f4::kEventOn);
  EXPECT_EQ(d::kEventOff, src::f4::kEventOff);
  EXPECT_EQ(d::kProfilePaused, src::f4::kStatusProfilePaused);
  EXPECT_EQ(d::kConstant1, src::f4::kStatusConstant);
  EXPECT_EQ(d::kProfileRunning, 2);  // CCL get_status:545-554
  EXPECT_EQ(d::kUnitsFahrenheit, src::f4::kUnitsFahrenheit);
}

// An F4T in Data Map 2: the limited set TestEquity lists (F4T manual p. 47, 101H manual p. 61),
// nothing more: no status, no setpoint limits, no input units.
TEST(Conformance, WatlowF4tMap2IsTheDocumentedSet) {
  namespace d = station::drivers::watlow_f4;
  for (int event = 1; event <= 8; ++event)
    for (int hum : {0, 2, 3}) {
      SCOPED_TRACE(fmt::format("run event {} humidity event {}", event, hum));
      check(d::map2(1, event, hum), src::f4t_map2::points(event, hum));
    }
  const auto m = d::map2();
  for (const char* absent :
       {d::kStatus, d::kSetpointLow, d::kSetpointHigh, d::kInput1Units, d::kInput2Units})
    EXPECT_EQ(m.find(absent), nullptr) << absent << " is not in Data Map 2";
}

// CCL watlowf4t.py / modbus.py; ramp registers from the TestEquity F4T manual as issue 20 quotes.
TEST(Conformance, WatlowF4tMatchesDataMap1) {
  namespace t = station::drivers::watlow_f4t;
  for (int event = 1; event <= 8; ++event)
    for (const bool rtu : {false, true})
      for (int loop = 1; loop <= 3; ++loop) {
        SCOPED_TRACE(fmt::format("event {} rtu {} loop {}", event, rtu, loop));
        check(t::map(1, event, rtu, loop), src::f4t::points(event, rtu, loop));
      }
  EXPECT_EQ(t::kOn, src::f4t::kOn);
  EXPECT_EQ(t::kOff, src::f4t::kOff);
  EXPECT_EQ(t::kAuto, src::f4t::kAuto);
  EXPECT_EQ(t::kManual, src::f4t::kManual);
  EXPECT_EQ(t::kProfilePaused, src::f4t::kProfilePaused);
  EXPECT_EQ(t::kProfileRunning, 149);  // CCL get_status:528-546
  EXPECT_EQ(t::kCelsius, src::f4t::kCelsius);
  EXPECT_EQ(t::kFahrenheit, src::f4t::kFahrenheit);
  EXPECT_EQ(t::kHours, src::f4t::kHours);
  EXPECT_EQ(t::kMinutes, src::f4t::kMinutes);
  EXPECT_EQ(t::kRampSetpoint, src::f4t::kRampSetpoint);
  EXPECT_EQ(t::kAlarmInactive, (std::array<int, 3>{88, 61, 12}));  // CCL get_alarm_status:552
  EXPECT_EQ(t::kAlarmInactive[1], src::f4t::kAlarmNone);
  EXPECT_EQ(t::kAlarmError, src::f4t::kAlarmError);  // CCL dictionary:81
  EXPECT_EQ(t::kPartNumberRegisters, src::f4t::kPartNumberRegisters);
  EXPECT_EQ(t::kAbsoluteTemperature, src::f4t::kAbsoluteTemperature);  // CCL __init__:112
  EXPECT_EQ(t::kRelativeTemperature, src::f4t::kRelativeTemperature);
  EXPECT_EQ(t::kHumidity, src::f4t::kHumidity);
  EXPECT_EQ(t::kDefaultHumidityEvent, src::f4::kHumidityEventNumber);  // TestEquity p. 51
  for (int hum : {0, 1, 2, 5})
    check(t::map(1, 1, false, 1, hum), src::f4t::points(1, false, 1, hum));
  // A float goes low word first (CCL modbus.py read_holding_float:157-173): 25.0 = 0x41C80000.
  const auto w = mb::float_to_words(25.0f, WordOrder::cdab);
  EXPECT_EQ(w[0], 0x0000);
  EXPECT_EQ(w[1], 0x41C8);
}

// Watlow Series F4P User's Manual 0600-0032-0013 Rev E, pages as printed.
TEST(Conformance, WatlowF4pMatchesItsManual) {
  namespace d = station::drivers::watlow_f4p;
  check(d::map(1), src::f4p::points());
  EXPECT_EQ(d::kModelF4p, src::f4p::kModelF4p);
  EXPECT_EQ(d::kAuto, src::f4p::kAuto);
  EXPECT_EQ(d::kManual, src::f4p::kManual);
  EXPECT_EQ(d::kRampOff, src::f4p::kRampOff);
  EXPECT_EQ(d::kRampStartupOrChange, src::f4p::kRampMax);
  EXPECT_EQ(d::kPerMinute, src::f4p::kPerMinute);
  EXPECT_EQ(d::kPerHour, src::f4p::kPerHour);
  EXPECT_EQ(d::kUnitsFahrenheit, src::f4p::kUnitsFahrenheit);
  EXPECT_EQ(d::kUnitsCelsius, src::f4p::kUnitsCelsius);
}

// The simulator's scaling of a Watlow integer (F4P p. 6.11, 6.13) against the driver's codec:
// two readings of the same pages, over every decimal setting and both units.
TEST(Conformance, WatlowScalingAgreesWithTheDriversCodec) {
  for (int decimals = 0; decimals <= 3; ++decimals)
    for (const bool f : {false, true})
      for (const double c : {-73.3, -40.0, 0.0, 0.04, 23.45, 85.0, 150.0}) {
        const station::drivers::TemperatureScale s{decimals, f};
        const double raw = src::watlow_raw(c, decimals, f);
        const auto want = s.raw_from_c(c);
        if (!want) {
          EXPECT_TRUE(raw == 32767 || raw == -32768) << c << " C, " << decimals;
          continue;
        }
        EXPECT_EQ(raw, *want) << c << " C, " << decimals << " decimals, F " << f;
        const auto r16 = static_cast<std::int16_t>(raw);
        EXPECT_DOUBLE_EQ(src::watlow_c_of_raw(r16, decimals, f), s.c_from_raw(r16));
      }
  EXPECT_EQ(src::watlow_raw(25.0, 1, true), 770);  // 77.0 F
  EXPECT_DOUBLE_EQ(src::watlow_c(212.0, true), 100.0);
}

// CCL p300.py / especinteract.py: spellings and the replies as the library parses them.
TEST(Conformance, EspecP300MatchesChamberConnectLibrary) {
  namespace p = station::drivers::espec_p300;
  namespace q = src::p300;  // what the simulator answers
  for (const auto& [driver, source] : std::vector<std::pair<std::string_view, std::string_view>>{
           {p::kTempQuery, q::kTempQuery},
           {p::kMonitorQuery, q::kMonitorQuery},
           {p::kModeQuery, q::kModeQuery},
           {p::kAlarmQuery, q::kAlarmQuery},
           {p::kProductQuery, q::kProductQuery},
           {p::kRomQuery, q::kRomQuery},
           {p::kModeConstant, q::kModeConstant},
           {p::kModeStandby, q::kModeStandby},
           {p::kModeOff, q::kModeOff},
           {p::kPowerOn, q::kPowerOn},
           {p::kErrorPrefix, q::kError}})
    EXPECT_EQ(driver, source);
  EXPECT_EQ(p::temp_setpoint_command(25).substr(0, q::kTempSetPrefix.size()), q::kTempSetPrefix);
  EXPECT_EQ(p::kTcpPort, 10001);                           // EspecTCP.__init__:117
  EXPECT_EQ(p::kTerminator, "\r\n");                       // EspecSerial.__init__:55
  EXPECT_EQ(p::temp_setpoint_command(25), "TEMP, S25.0");  // write_temp:1037 ("TEMP, S%0.1f")
  EXPECT_EQ(p::temp_setpoint_command(-40.04), "TEMP, S-40.0");
  EXPECT_EQ(p::addressed("TEMP?", 1), "1,TEMP?");  // EspecSerial.interact:93 ("%d,%s")
  EXPECT_EQ(p::addressed("TEMP?", 0), "TEMP?");
  EXPECT_EQ(p::kModeConstant, "MODE,CONSTANT");           // write_mode_constant:1148
  EXPECT_EQ(p::kModeStandby, "MODE,STANDBY");             // write_mode_standby:1142
  EXPECT_EQ(p::kPowerOn, "POWER,ON");                     // write_power:1014
  EXPECT_EQ(p::kProductQuery, "TEMP PTC?");               // read_temp_ptc:689
  const auto t = p::parse_temp("23.5,25.0,100.0,-40.0");  // read_temp: pv, sp, high, low
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->pv_c, 23.5);
  EXPECT_DOUBLE_EQ(t->low_c, -40.0);
  const auto m = p::parse_mon("25.0,,CONSTANT,0");  // read_mon: no humidity -> empty field
  ASSERT_TRUE(m);
  EXPECT_EQ(m->mode, "CONSTANT");
  EXPECT_EQ(m->alarms, 0);
  EXPECT_EQ(p::parse_alarm("2,7,21").value(), (std::vector<int>{7, 21}));  // field 0 skipped
  EXPECT_DOUBLE_EQ(p::parse_product("ON,24.1,25.0,25.0,24.0,10.0,10.0").value(), 24.1);
  std::string msg;
  EXPECT_TRUE(p::is_error("NA:CMD ERR", &msg));  // EspecSerial.interact:103
  EXPECT_EQ(msg, "CMD ERR");
  EXPECT_FALSE(p::parse_temp("23.5,25.0,100.0"));  // three fields: refused, never guessed
  EXPECT_FALSE(p::parse_mon("25.0,,BOGUS,0"));
}

// Acutronic TM-8004 command language (ACL), TM-9384C (TCP), acutrol3000.py (py).
TEST(Conformance, Acutrol3000MatchesItsCommandLanguage) {
  namespace a = station::drivers::acutrol3000;
  EXPECT_EQ(a::kTcpPort, 9878);                         // TCP p. 1
  EXPECT_EQ(a::kModeOff, ":Mode:Off 1");                // ACL p. 150; py `:mode:off 1`
  EXPECT_EQ(a::kModePosition, ":Mode:Position 1");      // ACL p. 151
  EXPECT_EQ(a::kModeRate, ":Mode:Rate 1");              // ACL p. 152
  EXPECT_EQ(a::kInterlockClose, ":Interlock:Close 1");  // ACL p. 131; py `:int:close 1`
  EXPECT_EQ(a::kInterlockReset, ":Interlock:Reset");    // ACL p. 136 (no axis)
  EXPECT_EQ(a::kRateLimitQuery, ":Limit:Rate? R,1");    // ACL p. 145 (mode, axis)
  EXPECT_EQ(a::position_demand(135.223), ":Demand:Position 1,135.22300");  // ACL p. 112
  EXPECT_EQ(a::rate_demand(-1.11111), ":Demand:Rate 1,-1.11111");          // ACL p. 113
  EXPECT_EQ(a::parse_number("170.00000").value(), 170.0);                  // NR2, ACL p. 112
  EXPECT_EQ(a::parse_number("-32.19877").value(), -32.19877);
  EXPECT_FALSE(a::parse_number("1.0e3x"));
  const auto pr = a::parse_position_rate("10.0001;44.1250");  // ACL p. 168: ';'-separated
  ASSERT_TRUE(pr);
  EXPECT_DOUBLE_EQ(pr->second, 44.125);
  EXPECT_EQ(a::parse_mode("Position"), a::Mode::position);  // py :121 (the real unit's word)
  EXPECT_EQ(a::parse_mode("P"), a::Mode::position);         // ACL p. 147 (a letter)
  EXPECT_EQ(a::parse_mode("Rate\r"), a::Mode::rate);
  EXPECT_EQ(a::parse_interlock("Fault"), a::Interlock::fault);  // py :41
  EXPECT_DOUBLE_EQ(a::wrap_deg(-90.0), 270.0);  // +-180 reported, [0, 360) inside the station
}

// The driver's spellings, read by the simulator's own transcription of the ACL command tree
// (sim_devices/sources/acutrol_sources.cpp): each names the command it means, in the form it
// means, and the framing and error-reading constants agree with the transcribed ones.
TEST(Conformance, Acutrol3000CommandsResolveInTheTranscribedTree) {
  namespace a = station::drivers::acutrol3000;
  namespace src = station::sim::sources::acutrol;
  const auto resolved = [](std::string_view command) {
    std::string out;
    for (const auto& u : station::sim::parse_acl(command)) {
      EXPECT_EQ(u.error, 0u) << command << ": " << u.why;
      out += (out.empty() ? "" : " ") + u.path + (u.query ? "?" : "");
      for (const auto& arg : u.args) out += " " + arg;
    }
    return out;
  };
  EXPECT_EQ(resolved(a::kIdentify), "*IDN?");
  EXPECT_EQ(resolved(a::kModeOff), ":Mode:Off 1");
  EXPECT_EQ(resolved(a::kModePosition), ":Mode:Position 1");
  EXPECT_EQ(resolved(a::kModeRate), ":Mode:Rate 1");
  EXPECT_EQ(resolved(a::kModeQuery), ":Mode? 1");
  EXPECT_EQ(resolved(a::kReadPositionRate), ":Read:Position? 1 :Read:Rate? 1");
  EXPECT_EQ(resolved(a::kInterlockQuery), ":Interlock? 1");
  EXPECT_EQ(resolved(a::kInterlockClose), ":Interlock:Close 1");
  EXPECT_EQ(resolved(a::kInterlockReset), ":Interlock:Reset");
  EXPECT_EQ(resolved(a::kRateLimitQuery), ":Limit:Rate? R 1");
  EXPECT_EQ(resolved(a::kPositionDemandQuery), ":Demand:Position? 1");
  EXPECT_EQ(resolved(a::kRateDemandQuery), ":Demand:Rate? 1");
  EXPECT_EQ(resolved(a::position_demand(1.5)), ":Demand:Position 1 1.50000");
  EXPECT_EQ(resolved(a::rate_demand(-2)), ":Demand:Rate 1 -2.00000");
  EXPECT_EQ(resolved(a::kClearStatus), "*CLS");
  EXPECT_EQ(resolved(a::kStatusByteQuery), "*STB?");
  EXPECT_EQ(resolved(a::kErrorQueueRead), ":Status:MSG? " + std::string(src::kErrorQueueId));
  EXPECT_EQ(resolved(a::error_text_query(3)), ":Query:Error? 3");
  EXPECT_EQ(a::kErrorQueueBit, src::kStbErrorQueue);
  EXPECT_EQ(a::kFrame.header_bytes, src::kHeaderBytes);
  EXPECT_EQ(a::kFrame.max_payload_bytes, src::kMaxResponseChars);
  EXPECT_EQ(a::kCommandTerminator, src::kBareEnd);  // CR LF both ways ([ACL] p. 4, [RN] p. 5)
  EXPECT_TRUE(src::kBareEnd.ends_with(a::kReplyTerminator));
}

}  // namespace
