// Register-map codec, endpoint parsing, presets and overrides (no I/O).
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "drivers/modbus/register_map.hpp"
#include "drivers/registry/dialects.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

namespace {

template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

}  // namespace

TEST(ModbusCodec, Float32WordOrderMatchesIeeeBitPattern) {
  // IEEE 754: 1.0f = 0x3F800000, -2.5f = 0xC0200000.
  EXPECT_EQ(mb::float_to_words(1.0f, mb::WordOrder::abcd),
            (std::array<std::uint16_t, 2>{0x3F80, 0}));
  EXPECT_EQ(mb::float_to_words(1.0f, mb::WordOrder::cdab),
            (std::array<std::uint16_t, 2>{0, 0x3F80}));
  const std::uint16_t cdab[2] = {0x0000, 0xC020};
  EXPECT_EQ(mb::words_to_float(cdab, mb::WordOrder::cdab), -2.5f);
  EXPECT_NE(mb::words_to_float(cdab, mb::WordOrder::abcd), -2.5f);
}

TEST(ModbusCodec, Float32CdabRoundTripsEveryTestValue) {
  for (float v : {0.0f, -40.0f, 70.125f, 1e-7f, -3.4e38f, 123456.789f}) {
    for (auto order : {mb::WordOrder::abcd, mb::WordOrder::cdab}) {
      auto w = mb::float_to_words(v, order);
      EXPECT_EQ(mb::words_to_float(w.data(), order), v) << v;
    }
  }
}

TEST(ModbusCodec, ScaledInt16EncodesNegativeAndRejectsOverflow) {
  mb::Point p{"t", 100, mb::PointType::int16, 0.1};
  auto w = mb::encode_point(p, -40.0);
  ASSERT_TRUE(w);
  EXPECT_EQ((*w)[0], static_cast<std::uint16_t>(-400));
  EXPECT_DOUBLE_EQ(mb::decode_point(p, w->data()), -40.0);
  EXPECT_FALSE(mb::encode_point(p, 3276.8));  // 32768 raw does not fit int16
  EXPECT_FALSE(mb::encode_point(p, NAN));
  mb::Point u{"u", 1, mb::PointType::uint16};
  EXPECT_FALSE(mb::encode_point(u, -1));
  EXPECT_TRUE(mb::encode_point(u, 65535));
}

TEST(ModbusCodec, OneBasedAddressIsShiftedOnTheWire) {
  mb::Point p{"x", 40001};
  p.one_based = true;
  EXPECT_EQ(p.pdu_address(), 40000);
}

TEST(ModbusEndpoint, ParsesTcpAndRtu) {
  auto tcp = std::get<mb::TcpEndpoint>(mb::parse_endpoint("tcp://10.0.0.5:1502"));
  EXPECT_EQ(tcp.host, "10.0.0.5");
  EXPECT_EQ(tcp.port, 1502);
  auto rtu = std::get<mb::RtuEndpoint>(
      mb::parse_endpoint("rtu:/dev/ttyUSB0?baud=9600&parity=E&data=8&stop=2"));
  EXPECT_EQ(rtu.device, "/dev/ttyUSB0");
  EXPECT_EQ(rtu.baud, 9600);
  EXPECT_EQ(rtu.parity, 'E');
  EXPECT_EQ(rtu.stop_bits, 2);
  auto def = std::get<mb::RtuEndpoint>(mb::parse_endpoint("rtu:/dev/ttyS1"));
  EXPECT_EQ(def.baud, 19200);
  EXPECT_EQ(mb::to_string(mb::parse_endpoint(mb::to_string(rtu))), mb::to_string(rtu));
}

TEST(ModbusEndpoint, ErrorsNameWhatIsWrong) {
  EXPECT_NE(error_of([] { mb::parse_endpoint("udp://x:1"); }).find("scheme"), std::string::npos);
  EXPECT_NE(error_of([] { mb::parse_endpoint("tcp://host"); }).find("PORT"), std::string::npos);
  EXPECT_NE(error_of([] { mb::parse_endpoint("tcp://h:70000"); }).find("port 70000"),
            std::string::npos);
  EXPECT_NE(error_of([] { mb::parse_endpoint("tcp://h:x1"); }).find("'x1' is not an integer"),
            std::string::npos);
  EXPECT_NE(error_of([] { mb::parse_endpoint("rtu:/dev/x?parity=Q"); }).find("parity 'Q'"),
            std::string::npos);
  EXPECT_NE(
      error_of([] { mb::parse_endpoint("rtu:/dev/x?speed=9600"); }).find("unknown option 'speed'"),
      std::string::npos);
  EXPECT_NE(error_of([] { mb::parse_endpoint("rtu:ttyS0"); }).find("absolute path"),
            std::string::npos);
}

TEST(ChamberMap, DialectMapsByModelAndUnknownModelIsNamed) {
  station::drivers::DeviceSpec spec;
  spec.endpoint = "tcp://127.0.0.1:502";
  auto plc = station::drivers::chamber_dialect("generic_plc").map(spec);
  EXPECT_EQ(plc.at(cm::kAir).address, 100);
  EXPECT_EQ(plc.at(cm::kRun).address, 2000);
  auto f4t = station::drivers::chamber_dialect("f4t").map(spec);  // the old preset's name
  EXPECT_EQ(f4t.at("loop1_pv").type, mb::PointType::float32);
  EXPECT_EQ(f4t.at("loop1_pv").order, mb::WordOrder::cdab);
  EXPECT_NE(error_of([] { station::drivers::chamber_dialect("espec"); }).find("'espec'"),
            std::string::npos);
  EXPECT_NE(error_of([&] { (void)plc.at("nope"); }).find("'nope'"), std::string::npos);
  EXPECT_EQ(station::drivers::turntable_map::generic_plc().points().size(), 9u);
  EXPECT_FALSE(station::drivers::chamber_dialect("espec_p300").map);  // ASCII: no map
}

TEST(ChamberMap, OverridesChangeOnlyNamedFieldsAndAreChecked) {
  auto map = cm::generic_plc();
  mb::PointOverride o{.name = cm::kAir, .address = 4001, .one_based = true};
  mb::apply_overrides(map, {o});
  EXPECT_EQ(map.at(cm::kAir).pdu_address(), 4000);
  EXPECT_EQ(map.at(cm::kAir).scale, 0.1);
  auto unknown = mb::PointOverride{.name = "humidity"};
  EXPECT_NE(error_of([&] { mb::apply_overrides(map, {unknown}); }).find("'humidity'"),
            std::string::npos);
  auto zero = mb::PointOverride{.name = cm::kProduct, .scale = 0.0};
  EXPECT_NE(error_of([&] { mb::apply_overrides(map, {zero}); }).find("scale"), std::string::npos);
  EXPECT_EQ(mb::parse_word_order("cdab"), mb::WordOrder::cdab);
  EXPECT_EQ(mb::parse_function_code("4"), mb::FunctionCode::input);
  EXPECT_NE(error_of([] { mb::parse_point_type("int32"); }).find("'int32'"), std::string::npos);
}
