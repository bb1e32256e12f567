// Issue 20: each dialect's shared wire definition (what driver AND simulator use) against a table
// transcribed by hand from the maker's document or public client library, so a wrong address,
// type, word order or spelling is a failing test, not a consistent error on both sides. The
// tables below are the transcription; docs/DEVICES.md cites the same sources per point.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "drivers/chamber/espec_p300/p300_wire.hpp"
#include "drivers/chamber/watlow_f4/f4_map.hpp"
#include "drivers/chamber/watlow_f4p/f4p_map.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"

namespace {

namespace mb = station::drivers::modbus;
using mb::PointType;
using mb::WordOrder;

struct Row {
  const char* point;
  int address;  // 0-based PDU address, as the source gives it
  PointType type;
  WordOrder order;
  bool writable;
  const char* source;
};

void check(const mb::RegisterMap& map, const std::vector<Row>& rows) {
  for (const auto& r : rows) {
    SCOPED_TRACE(std::string(r.point) + " (" + r.source + ")");
    const auto* p = map.find(r.point);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(p->pdu_address(), r.address);
    EXPECT_EQ(p->type, r.type);
    if (r.type == PointType::float32) {
      EXPECT_EQ(p->order, r.order);
    }
    EXPECT_EQ(p->function, mb::FunctionCode::holding);  // all three use holding registers only
    EXPECT_EQ(p->access == mb::Access::rw, r.writable);
    EXPECT_EQ(p->scale, 1.0);  // raw on the wire; decimals/units are read from the unit
  }
}

constexpr auto I16 = PointType::int16;
constexpr auto U16 = PointType::uint16;
constexpr auto F32 = PointType::float32;
constexpr auto CDAB = WordOrder::cdab;
constexpr auto ABCD = WordOrder::abcd;

// ESPEC ChamberConnectLibrary @1d2deb8 watlowf4.py (CCL) and the Watlow F4P manual Rev E (F4P).
TEST(Conformance, WatlowF4MatchesChamberConnectLibrary) {
  check(station::drivers::watlow_f4::map(1, 3),
        {{"input1_pv", 100, I16, ABCD, false, "CCL get_loop_pv:349"},
         {"input1_err", 101, U16, ABCD, false, "F4P p. 9.6"},
         {"input2_pv", 104, I16, ABCD, false, "CCL get_loop_pv:349 (loop 2)"},
         {"status", 200, U16, ABCD, false, "CCL get_status:545"},
         {"setpoint1", 300, I16, ABCD, true, "CCL get_loop_sp:329, set_loop_sp:342"},
         {"sp_low1", 602, I16, ABCD, false, "CCL get_loop_range:354"},
         {"sp_high1", 603, I16, ABCD, false, "CCL get_loop_range:354"},
         {"decimals1", 606, U16, ABCD, false, "CCL __get_scalar:100"},
         {"decimals2", 616, U16, ABCD, false, "CCL __get_scalar:100"},
         {"units", 901, U16, ABCD, false, "CCL get_loop_units:396"},
         {"event", 2020, U16, ABCD, true, "CCL get_event:533 (2000 + 10(n-1), n = 3)"}});
  EXPECT_EQ(station::drivers::watlow_f4::kEventOn, 1);  // CCL set_event:539-543
  EXPECT_EQ(station::drivers::watlow_f4::kEventOff, 0);
  EXPECT_EQ(station::drivers::watlow_f4::kProfileRunning, 2);  // CCL get_status:545-554
  EXPECT_EQ(station::drivers::watlow_f4::kProfilePaused, 3);
  EXPECT_EQ(station::drivers::watlow_f4::kUnitsFahrenheit, 0);  // F4P p. 6.11
}

// CCL watlowf4t.py / modbus.py; ramp registers from the TestEquity F4T manual as issue 20 quotes.
TEST(Conformance, WatlowF4tMatchesDataMap1) {
  check(station::drivers::watlow_f4t::map(1, 5, false, 1),
        {{"loop1_pv", 2820, F32, CDAB, false, "CCL get_loop_pv:243; modbus.py low_word_first"},
         {"loop2_pv", 2980, F32, CDAB, false, "CCL get_loop_pv:243 (+160 per loop)"},
         {"loop1_sp", 2782, F32, CDAB, true, "CCL get_loop_sp:234, set_loop_sp:241"},
         {"loop1_wsp", 2810, F32, CDAB, false, "CCL get_loop_sp:235"},
         {"loop1_sp_min", 2774, F32, CDAB, false, "CCL get_loop_range:256"},
         {"loop1_sp_max", 2776, F32, CDAB, false, "CCL get_loop_range:256"},
         {"loop1_mode", 2814, U16, ABCD, false, "CCL get_loop_en:264"},
         {"loop1_ramp_action", 2794, U16, ABCD, true, "TestEquity F4T manual (issue 20)"},
         {"loop1_ramp_scale", 2796, U16, ABCD, true, "TestEquity F4T manual (issue 20)"},
         {"loop1_ramp_rate", 2798, F32, CDAB, true, "TestEquity F4T manual (issue 20)"},
         {"profile_state", 16568, U16, ABCD, false, "CCL get_status:528"},
         {"alarm1_state", 1356, U16, ABCD, false, "CCL get_alarm_status:552"},
         {"event", 16822, U16, ABCD, true, "CCL get_event:499 (event 5)"},
         {"units", 6730, U16, ABCD, false, "CCL __profile_units:1003 (TCP)"},
         {"part_number_0", 16, U16, ABCD, false, "CCL process_controller:861"}});
  EXPECT_EQ(station::drivers::watlow_f4t::map(1, 1, true).at("units").address, 14080);  // RTU
  EXPECT_EQ(station::drivers::watlow_f4t::map(1, 1, false, 2).at("loop1_pv").address, 2980);
  namespace t = station::drivers::watlow_f4t;
  EXPECT_EQ(t::kOn, 63);  // CCL set_event:508-520
  EXPECT_EQ(t::kOff, 62);
  EXPECT_EQ(t::kAuto, 10);  // CCL set_loop_mode:294-309
  EXPECT_EQ(t::kManual, 54);
  EXPECT_EQ(t::kProfileRunning, 149);  // CCL get_status:528-546
  EXPECT_EQ(t::kProfilePaused, 146);
  EXPECT_EQ(t::kCelsius, 15);  // CCL __profile_units
  EXPECT_EQ(t::kFahrenheit, 30);
  EXPECT_EQ(t::kAlarmInactive, (std::array<int, 3>{88, 61, 12}));  // CCL get_alarm_status:552
  // A float goes low word first (CCL modbus.py read_holding_float:157-173): 25.0 = 0x41C80000.
  const auto w = mb::float_to_words(25.0f, CDAB);
  EXPECT_EQ(w[0], 0x0000);
  EXPECT_EQ(w[1], 0x41C8);
}

// Watlow Series F4P User's Manual 0600-0032-0013 Rev E, pages as printed.
TEST(Conformance, WatlowF4pMatchesItsManual) {
  check(station::drivers::watlow_f4p::map(1), {{"model", 0, U16, ABCD, false, "p. 6.27"},
                                               {"input1_pv", 100, I16, ABCD, false, "p. 9.6"},
                                               {"input1_err", 101, U16, ABCD, false, "p. 9.6"},
                                               {"alarm1_status", 102, U16, ABCD, false, "p. 9.2"},
                                               {"auto_manual", 200, U16, ABCD, true, "p. 9.2"},
                                               {"control_sp", 298, I16, ABCD, false, "p. 9.4"},
                                               {"setpoint1", 300, I16, ABCD, true, "p. 9.9"},
                                               {"sp_low1", 602, I16, ABCD, false, "p. 6.13"},
                                               {"sp_high1", 603, I16, ABCD, false, "p. 6.13"},
                                               {"decimals1", 606, U16, ABCD, false, "p. 6.13"},
                                               {"units", 901, U16, ABCD, false, "p. 6.11"},
                                               {"ramp_mode", 1100, U16, ABCD, true, "p. 6.7"},
                                               {"ramp_rate", 1101, I16, ABCD, true, "p. 6.8"},
                                               {"ramp_scale", 1102, U16, ABCD, true, "p. 6.8"}});
  EXPECT_EQ(station::drivers::watlow_f4p::kModelF4p, 5280);  // "P4 (4P) ASCII 5280 Dec"
}

// CCL p300.py / especinteract.py: spellings and the replies as the library parses them.
TEST(Conformance, EspecP300MatchesChamberConnectLibrary) {
  namespace p = station::drivers::espec_p300;
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

}  // namespace
