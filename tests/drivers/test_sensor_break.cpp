// Issue 33 point 3: a broken air sensor over a real socket. The F4T's loop PV reads NaN on an
// input error (docs/DEVICES.md: A) and its alarm 1 reads "error": the driver reports a sensor
// break with air NaN, never a protocol error retried for ever nor a frozen value. The Modbus
// client's rule: NaN reaches the driver only from a point that may carry it (a process value).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/chamber/watlow_f4t/watlow_f4t_chamber.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/watlow_faces.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace {

namespace dr = station::drivers;
namespace mb = station::drivers::modbus;
namespace sim = station::sim;

struct F4tRig {
  F4tRig() : face(chamber, sim::WatlowPanel{}), server(face, 1) {
    server.start_tcp(0);
    driver = std::make_unique<dr::WatlowF4tChamber>(
        "chamber", mb::parse_endpoint(server.endpoint()), dr::watlow_f4t::map(), 0.5);
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4tFace face;
  sim::ModbusServer server;
  std::unique_ptr<dr::WatlowF4tChamber> driver;
};

TEST(SensorBreak, F4tBrokenAirSensorIsASensorBreakWithNanAirNotAnError) {
  F4tRig rig;
  auto good = rig.driver->read();
  ASSERT_TRUE(good) << good.error().message;
  EXPECT_FALSE(good.value().alarms.sensor_break);
  const double air_c = good.value().air_c;
  ASSERT_TRUE(std::isfinite(air_c));

  rig.chamber.set_air_sensor_failed(true);
  const auto connects = rig.driver->client().connects();
  for (int i = 0; i < 3; ++i) {  // every read while broken, not only the first
    auto s = rig.driver->read();
    ASSERT_TRUE(s) << "read " << i << ": " << s.error().message;
    EXPECT_TRUE(s.value().alarms.sensor_break);
    EXPECT_TRUE(std::isnan(s.value().air_c)) << s.value().air_c;  // not the frozen last value
    EXPECT_FALSE(s.value().alarms.deviation);  // alarm 1 in "error" is its input, not a deviation
  }
  EXPECT_EQ(rig.driver->client().connects(), connects);  // no reconnect: not a link fault
  // On the wire: register 2820 carries NaN and alarm 1 (1356) reads "error" (28), not "none".
  auto pv = rig.driver->client().read(dr::watlow_f4t::map().at(dr::watlow_f4t::kAir));
  ASSERT_TRUE(pv) << pv.error().message;
  EXPECT_TRUE(std::isnan(pv.value()));
  auto alarm = rig.driver->client().read(dr::watlow_f4t::map().at(dr::watlow_f4t::kAlarm1));
  ASSERT_TRUE(alarm) << alarm.error().message;
  EXPECT_EQ(alarm.value(), dr::watlow_f4t::kAlarmError);

  rig.chamber.set_air_sensor_failed(false);
  auto back = rig.driver->read();
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back.value().alarms.sensor_break);
  EXPECT_NEAR(back.value().air_c, air_c, 0.5);
}

// A device serving two floats that both read NaN: a process value (may carry NaN) and a
// setpoint (may not).
class NanDevice : public sim::ModbusDeviceModel {
 public:
  NanDevice()
      : map_("nan_device", {mb::Point{"pv", 10, mb::PointType::float32, 1.0, mb::WordOrder::cdab,
                                      mb::FunctionCode::holding, 1, false, mb::Access::ro, true},
                            mb::Point{"sp", 12, mb::PointType::float32, 1.0, mb::WordOrder::cdab,
                                      mb::FunctionCode::holding, 1, false, mb::Access::rw}}) {}
  const mb::RegisterMap& register_map() const override { return map_; }
  int register_count() const override { return sim::register_count(map_); }
  void publish(modbus_mapping_t& regs) override {
    sim::put_point(regs, map_.at("pv"), NAN);
    sim::put_point(regs, map_.at("sp"), NAN);
  }
  void on_write(const modbus_mapping_t&, std::uint16_t, int) override {}

 private:
  mb::RegisterMap map_;
};

TEST(SensorBreak, NanReachesTheDriverOnlyFromAProcessValue) {
  NanDevice device;
  sim::ModbusServer server(device, 1);
  server.start_tcp(0);
  mb::ModbusClient client("nan_device", mb::parse_endpoint(server.endpoint()), 0.5);
  const auto& map = device.register_map();
  auto pv = client.read(map.at("pv"));
  ASSERT_TRUE(pv) << pv.error().message;
  EXPECT_TRUE(std::isnan(pv.value()));
  auto sp = client.read(map.at("sp"));
  ASSERT_FALSE(sp);
  EXPECT_EQ(sp.error().kind, dr::ErrorKind::protocol);
  EXPECT_NE(sp.error().message.find("'sp' is not finite"), std::string::npos) << sp.error().message;
  // The same rule for a planned block read.
  const std::vector<mb::Point> points{map.at("pv"), map.at("sp")};
  const auto plan = mb::plan_reads(points, 0);
  auto both = client.read_points(points, plan);
  ASSERT_FALSE(both);
  EXPECT_EQ(both.error().kind, dr::ErrorKind::protocol);
  const std::vector<mb::Point> pv_only{map.at("pv")};
  auto one = client.read_points(pv_only, mb::plan_reads(pv_only, 0));
  ASSERT_TRUE(one) << one.error().message;
  EXPECT_TRUE(std::isnan(one.value().at(0)));
}

}  // namespace
