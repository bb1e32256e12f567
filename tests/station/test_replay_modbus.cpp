// Issue 8, replay groundwork: a ModbusClient over a recorded session (RecordedModbusWire)
// gets, exchange by exchange, what the live device answered — values, timeouts, written
// setpoints — and asking for anything the recording does not hold is a divergence naming both
// requests. The session logs read plain or gzip-compressed.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "station/common/input_error.hpp"
#include "station/session/replay_modbus.hpp"
#include "station/session/session_log.hpp"
#include "station/session/session_recorder.hpp"

namespace fs = std::filesystem;
namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

namespace {

// What one sequence of calls gave: values, or the error's kind and message.
std::vector<std::string> exercise(mb::ModbusClient& c, const mb::RegisterMap& map,
                                  station::sim::ModbusServer* server) {
  std::vector<std::string> out;
  const auto note = [&out](const auto& r) {
    if constexpr (std::is_same_v<std::decay_t<decltype(r)>, station::drivers::Result<double>>)
      out.push_back(r ? std::to_string(r.value()) : r.error().message);
    else
      out.push_back(r ? "ok" : r.error().message);
  };
  note(c.read(map.at(cm::kAir)));
  note(c.write(map.at(cm::kSetpoint), -40.0));
  note(c.read(map.at(cm::kSetpoint)));
  if (server != nullptr) server->inject_timeouts(1);
  note(c.read(map.at(cm::kAir)));  // a timeout, live and replayed
  note(c.read(map.at(cm::kProduct)));
  return out;
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = ::testing::TempDir() + name + "-" + std::to_string(getpid());
  fs::remove_all(d);
  return d;
}

}  // namespace

TEST(ReplayModbus, AClientOverTheRecordingGetsWhatTheDeviceAnswered) {
  const auto dir = temp_dir("replay_modbus");
  const mb::RegisterMap map = cm::generic_plc();
  station::sim::ChamberSim sim{map};
  station::sim::ModbusServer server{sim};
  server.start_tcp();
  const auto endpoint = mb::parse_endpoint(server.endpoint());
  std::vector<std::string> live;
  {
    station::SessionRecorder rec(dir.string());
    mb::ModbusClient client("chamber", endpoint, 0.3);
    client.set_tap(&rec);
    live = exercise(client, map, &server);
    rec.flush();
  }
  ASSERT_EQ(live.size(), 5u);
  EXPECT_NE(live[3].find("timed out"), std::string::npos) << live[3];
  auto lines = station::read_session_log((dir / "modbus.log").string());
  auto wire = std::make_unique<station::RecordedModbusWire>("chamber", lines);
  auto* w = wire.get();
  mb::ModbusClient replay("chamber", endpoint, std::move(wire), 0.3);
  EXPECT_EQ(exercise(replay, map, nullptr), live);
  EXPECT_EQ(w->remaining(), 0u);

  // Another setpoint written: a divergence naming the device, both requests and the line.
  mb::ModbusClient diverging("chamber", endpoint,
                             std::make_unique<station::RecordedModbusWire>("chamber", lines), 0.3);
  ASSERT_TRUE(diverging.read(map.at(cm::kAir)));
  try {
    (void)diverging.write(map.at(cm::kSetpoint), -39.0);
    FAIL() << "no divergence";
  } catch (const station::ReplayDivergence& e) {
    EXPECT_EQ(e.device, "chamber");
    EXPECT_NE(e.recorded.find("tx modbus-write 0106012cfe70"), std::string::npos) << e.what();
    EXPECT_EQ(e.asked, "tx modbus-write 0106012cfe7a") << e.what();  // -39.0 C = -390
  }
}

TEST(ReplayModbus, LogsReadPlainOrGzipAndABadLineNamesFileAndLine) {
  const auto dir = temp_dir("session_log");
  fs::create_directories(dir);
  const std::string text =
      "1700000000.000001 chamber tx modbus-read 01030064000a unit=1 fc=3 addr=100 count=10\n"
      "1700000000.000002 chamber event error 0000006e chamber read: Connection timed out\n";
  {
    gzFile gz = gzopen((dir / "modbus.log.gz").c_str(), "wb");
    ASSERT_NE(gz, nullptr);
    gzwrite(gz, text.data(), static_cast<unsigned>(text.size()));
    gzclose(gz);
  }
  const auto lines = station::read_session_log((dir / "modbus.log").string());
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].bytes, (std::vector<std::uint8_t>{1, 3, 0, 100, 0, 10}));
  EXPECT_EQ(lines[0].detail, "unit=1 fc=3 addr=100 count=10");
  EXPECT_EQ(lines[1].kind, "error");
  EXPECT_EQ(lines[1].line_no, 2);
  std::ofstream(dir / "gpio.log") << "1700000000.1 gpio rx gpio-read 01 role=estop\n"
                                  << "1700000000.2 gpio sideways gpio-read 01 role=estop\n";
  try {
    station::read_session_log((dir / "gpio.log").string());
    FAIL() << "accepted a bad direction";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gpio.log:2: bad direction 'sideways'"), std::string::npos)
        << e.what();
  }
  std::ofstream(dir / "bad.log") << "1700000000.1 gpio rx gpio-read 0g role=estop\n";
  EXPECT_THROW(station::read_session_log((dir / "bad.log").string()), station::InputError);
}
