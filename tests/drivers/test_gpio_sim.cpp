// GPIO role-map config and the simulated bank: safe defaults, edges on a real fd, typed errors.
#include <gtest/gtest.h>
#include <poll.h>

#include <chrono>
#include <ctime>
#include <memory>
#include <stdexcept>
#include <thread>

#include "drivers/gpio/gpio_bank.hpp"
#include "sim_devices/gpio_sim.hpp"

using namespace station::drivers;
using namespace station::drivers::gpio;
using station::sim::GpioSimBank;
using station::sim::GpioSimChips;

namespace {

struct RecordingTap : Tap {
  std::vector<TapRecord> records;
  void on_exchange(const TapRecord& r) noexcept override { records.push_back(r); }
};

double monotonic_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Waits up to timeout_ms for POLLIN on fd; returns poll()'s result.
int wait_readable(int fd, int timeout_ms) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms);
}

// The station's lines: tower red is wired active-low (lamp lit when the pin is low), so is e-stop.
GpioConfig station_config() {
  return make_gpio_config({{"interlock", "DOOR_SW"},
                           {"estop", "!ESTOP"},
                           {"relay.1", "GYRO_PWR1"},
                           {"relay.2", "gpiochip0:3"},
                           {"tower.green", "TOWER_G"},
                           {"tower.amber", "TOWER_A"},
                           {"tower.red", "!TOWER_R"}});
}

std::shared_ptr<GpioSimChips> station_chips() {
  return std::make_shared<GpioSimChips>(std::vector<station::sim::GpioSimChipSpec>{
      {"gpiochip0",
       {"DOOR_SW", "ESTOP", "GYRO_PWR1", "GYRO_PWR2", "TOWER_G", "TOWER_A", "TOWER_R", ""}}});
}

}  // namespace

TEST(GpioConfig, RoleMapGivesDirectionsSafeLevelsAndWiring) {
  const GpioConfig c = station_config();
  ASSERT_EQ(c.lines.size(), 7u);
  const auto* estop = find_role(c, roles::estop);
  ASSERT_NE(estop, nullptr);
  EXPECT_EQ(estop->direction, GpioDirection::input);
  EXPECT_TRUE(estop->active_low);
  EXPECT_EQ(estop->line_name, "ESTOP");
  EXPECT_EQ(estop->chip, "gpiochip0");
  const auto* relay2 = find_role(c, roles::relay(2));
  ASSERT_NE(relay2, nullptr);
  EXPECT_EQ(relay2->direction, GpioDirection::output);
  EXPECT_FALSE(relay2->safe_level);
  EXPECT_EQ(relay2->offset, 3);
  EXPECT_TRUE(relay2->line_name.empty());
  EXPECT_EQ(relay2->where(), "gpiochip0:3");
  EXPECT_TRUE(find_role(c, roles::tower_red)->safe_level);
  EXPECT_FALSE(find_role(c, roles::tower_green)->safe_level);
  EXPECT_FALSE(find_role(c, roles::tower_amber)->safe_level);
  EXPECT_EQ(find_role(c, "relay.9"), nullptr);
}

TEST(GpioConfig, BadKeysAndSpecsThrowNamingTheKey) {
  auto message_of = [](const std::map<std::string, std::string>& m) -> std::string {
    try {
      (void)make_gpio_config(m);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(no exception)";
  };
  EXPECT_NE(message_of({{"door", "DOOR_SW"}}).find("'door'"), std::string::npos);
  EXPECT_NE(message_of({{"relay.0", "X"}}).find("'relay.0'"), std::string::npos);
  EXPECT_NE(message_of({{"relay.1x", "X"}}).find("'relay.1x'"), std::string::npos);
  EXPECT_NE(message_of({{"estop", "gpiochip0:"}}).find("'estop'"), std::string::npos);
  EXPECT_NE(message_of({{"estop", ":5"}}).find("empty chip"), std::string::npos);
  EXPECT_NE(message_of({{"estop", "!"}}).find("empty line"), std::string::npos);
  EXPECT_NE(message_of({{"relay.1", "GYRO_PWR1"}, {"relay.2", "!GYRO_PWR1"}}).find("same line"),
            std::string::npos);
}

TEST(GpioSim, OutputsStartAtSafeDefaults) {
  auto chips = station_chips();
  // Pins left in the unsafe state by whatever ran before us: relay energised, red lamp dark.
  chips->set_input("GYRO_PWR1", true);
  chips->set_input("TOWER_R", true);
  GpioSimBank bank(station_config(), chips);
  EXPECT_EQ(bank.event_fd(), -1);  // constructor does no I/O
  ASSERT_TRUE(bank.open().ok());
  EXPECT_EQ(chips->pin_level("GYRO_PWR1"), false);
  EXPECT_EQ(chips->pin_level("gpiochip0:3"), false);
  EXPECT_EQ(chips->pin_level("TOWER_G"), false);
  EXPECT_EQ(chips->pin_level("TOWER_A"), false);
  EXPECT_EQ(chips->pin_level("TOWER_R"), false);  // active-low: low = lit
  auto red = bank.read(roles::tower_red);
  ASSERT_TRUE(red.ok());
  EXPECT_TRUE(red.value());
  EXPECT_EQ(chips->consumer("DOOR_SW"), "gyro-station");
  EXPECT_EQ(chips->consumer("gpiochip0:7"), "");
}

TEST(GpioSim, InterlockOpeningIsAnEdgeOnThePollableFd) {
  auto chips = station_chips();
  chips->set_input("DOOR_SW", true);  // door closed before the station starts: no edge
  RecordingTap tap;  // outlives the bank, whose close() still taps the safe-state writes
  GpioSimBank bank(station_config(), chips);
  bank.set_tap(&tap);
  ASSERT_TRUE(bank.open().ok());
  ASSERT_GE(bank.event_fd(), 0);
  EXPECT_EQ(wait_readable(bank.event_fd(), 0), 0);
  EXPECT_TRUE(bank.read(roles::interlock).value());

  const double before_s = monotonic_s();
  std::thread door([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    chips->set_input("DOOR_SW", false);
  });
  const int ready = wait_readable(bank.event_fd(), 2000);
  door.join();
  const double after_s = monotonic_s();
  ASSERT_EQ(ready, 1) << "no event on the fd within 2 s";

  auto edges = bank.read_events();
  ASSERT_TRUE(edges.ok()) << edges.error().message;
  ASSERT_EQ(edges.value().size(), 1u);
  const GpioEdge& e = edges.value()[0];
  EXPECT_EQ(e.role, "interlock");
  EXPECT_EQ(e.line, "DOOR_SW");
  EXPECT_FALSE(e.rising);  // interlock broken = became inactive
  EXPECT_GE(e.timestamp_s, before_s);
  EXPECT_LE(e.timestamp_s, after_s);
  EXPECT_FALSE(bank.read(roles::interlock).value());
  EXPECT_EQ(wait_readable(bank.event_fd(), 0), 0);  // drained
  EXPECT_TRUE(bank.read_events().value().empty());

  // The edge, then the read after it.
  ASSERT_GE(tap.records.size(), 2u);
  EXPECT_EQ(tap.records.back().kind, "gpio-read");
  EXPECT_EQ(tap.records.back().direction, TapDirection::rx);
  EXPECT_EQ(tap.records.back().bytes, std::vector<std::uint8_t>{0});
  const TapRecord& r = tap.records[tap.records.size() - 2];
  EXPECT_EQ(r.kind, "gpio-edge");
  EXPECT_EQ(r.direction, TapDirection::event);
  EXPECT_EQ(r.bytes, std::vector<std::uint8_t>{0});
  EXPECT_NE(r.detail.find("role=interlock"), std::string::npos);
}

TEST(GpioSim, ActiveLowEstopAndEdgeOrder) {
  auto chips = station_chips();
  chips->set_input("ESTOP", true);  // released: pin pulled high
  GpioSimBank bank(station_config(), chips);
  ASSERT_TRUE(bank.open().ok());
  EXPECT_FALSE(bank.read(roles::estop).value());
  chips->set_input("ESTOP", false);  // pressed
  chips->set_input("ESTOP", false);  // no change, no edge
  chips->set_input("DOOR_SW", true);
  chips->set_input("ESTOP", true);  // released
  ASSERT_EQ(wait_readable(bank.event_fd(), 1000), 1);
  auto edges = bank.read_events();
  ASSERT_TRUE(edges.ok());
  ASSERT_EQ(edges.value().size(), 3u);
  EXPECT_EQ(edges.value()[0].role, "estop");
  EXPECT_TRUE(edges.value()[0].rising);  // pressed = became active
  EXPECT_EQ(edges.value()[1].role, "interlock");
  EXPECT_TRUE(edges.value()[1].rising);
  EXPECT_EQ(edges.value()[2].role, "estop");
  EXPECT_FALSE(edges.value()[2].rising);
  EXPECT_LE(edges.value()[0].timestamp_s, edges.value()[2].timestamp_s);
}

TEST(GpioSim, WritesDriveTheirPinsAndPassTheTap) {
  auto chips = station_chips();
  RecordingTap tap;  // outlives the bank, whose close() still taps the safe-state writes
  GpioSimBank bank(station_config(), chips);
  bank.set_tap(&tap);
  ASSERT_TRUE(bank.open().ok());
  EXPECT_EQ(tap.records.size(), 5u);  // the five outputs' safe levels at request time
  ASSERT_TRUE(bank.write(roles::relay(1), true).ok());
  ASSERT_TRUE(bank.write(roles::tower_red, false).ok());
  EXPECT_EQ(chips->pin_level("GYRO_PWR1"), true);
  EXPECT_EQ(chips->pin_level("TOWER_R"), true);  // active-low: high = dark
  EXPECT_TRUE(bank.read(roles::relay(1)).value());
  ASSERT_EQ(tap.records.size(), 8u);  // two writes and the read
  EXPECT_EQ(tap.records[7].kind, "gpio-read");
  EXPECT_EQ(tap.records[7].bytes, std::vector<std::uint8_t>{1});
  EXPECT_EQ(tap.records[5].kind, "gpio-write");
  EXPECT_EQ(tap.records[5].direction, TapDirection::tx);
  EXPECT_EQ(tap.records[5].bytes, std::vector<std::uint8_t>{1});
  EXPECT_NE(tap.records[5].detail.find("role=relay.1"), std::string::npos);
}

TEST(GpioSim, BadRolesAndWritesToInputsAreTypedErrors) {
  GpioSimBank bank(station_config(), station_chips());
  auto before = bank.read(roles::interlock);
  ASSERT_FALSE(before.ok());
  EXPECT_EQ(before.error().kind, ErrorKind::disconnected);
  ASSERT_TRUE(bank.open().ok());
  auto unknown = bank.write("relay.7", true);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().kind, ErrorKind::range);
  EXPECT_NE(unknown.error().message.find("relay.7"), std::string::npos);
  auto input = bank.write(roles::interlock, true);
  ASSERT_FALSE(input.ok());
  EXPECT_EQ(input.error().kind, ErrorKind::range);
  EXPECT_EQ(bank.read("door").error().kind, ErrorKind::range);
}

TEST(GpioSim, OutputsReturnToSafeOnCloseAndDestruction) {
  auto chips = station_chips();
  {
    GpioSimBank bank(station_config(), chips);
    ASSERT_TRUE(bank.open().ok());
    ASSERT_TRUE(bank.write(roles::relay(1), true).ok());
    ASSERT_TRUE(bank.write(roles::tower_green, true).ok());
    ASSERT_TRUE(bank.write(roles::tower_red, false).ok());
    bank.close();
    EXPECT_EQ(chips->pin_level("GYRO_PWR1"), false);
    EXPECT_EQ(chips->pin_level("TOWER_G"), false);
    EXPECT_EQ(chips->pin_level("TOWER_R"), false);  // lit
    EXPECT_EQ(chips->consumer("GYRO_PWR1"), "");
    EXPECT_EQ(bank.event_fd(), -1);
    bank.close();  // idempotent

    ASSERT_TRUE(bank.open().ok());  // reopen after close
    ASSERT_TRUE(bank.write(roles::relay(2), true).ok());
    ASSERT_TRUE(bank.write(roles::tower_amber, true).ok());
    ASSERT_TRUE(bank.write(roles::tower_red, false).ok());
    EXPECT_EQ(chips->pin_level("gpiochip0:3"), true);
  }
  EXPECT_EQ(chips->pin_level("gpiochip0:3"), false);
  EXPECT_EQ(chips->pin_level("TOWER_A"), false);
  EXPECT_EQ(chips->pin_level("TOWER_R"), false);
  EXPECT_EQ(chips->consumer("DOOR_SW"), "");
  chips->set_input("DOOR_SW", true);  // no bank listening any more: no crash, no event
}

TEST(GpioSim, BadLineNamesFailOpenWithTypedErrorsAndReleaseEverything) {
  auto chips = station_chips();
  auto with = [](const std::string& role, const std::string& spec) {
    auto m = std::map<std::string, std::string>{{"relay.1", "GYRO_PWR1"}, {role, spec}};
    return make_gpio_config(m);
  };
  GpioSimBank misnamed(with("interlock", "DOOR_SWITCH"), chips);
  auto r = misnamed.open();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::range);
  EXPECT_NE(r.error().message.find("DOOR_SWITCH"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("interlock"), std::string::npos) << r.error().message;
  EXPECT_EQ(chips->consumer("GYRO_PWR1"), "");  // the relay requested first was released
  EXPECT_EQ(misnamed.event_fd(), -1);

  GpioSimBank no_chip(with("estop", "gpiochip9:1"), chips);
  EXPECT_EQ(no_chip.open().error().kind, ErrorKind::disconnected);
  GpioSimBank bad_offset(with("estop", "gpiochip0:8"), chips);
  auto off = bad_offset.open();
  ASSERT_FALSE(off.ok());
  EXPECT_EQ(off.error().kind, ErrorKind::range);
  EXPECT_NE(off.error().message.find("0..7"), std::string::npos) << off.error().message;

  GpioSimBank first(station_config(), chips);
  GpioSimBank second(station_config(), chips);
  ASSERT_TRUE(first.open().ok());
  auto busy = second.open();
  ASSERT_FALSE(busy.ok());
  EXPECT_EQ(busy.error().kind, ErrorKind::io);
  EXPECT_NE(busy.error().message.find("busy"), std::string::npos) << busy.error().message;
  EXPECT_EQ(chips->consumer("DOOR_SW"), "gyro-station");  // first still holds its lines
}

TEST(GpioSim, TestApiRejectsUnknownAndOutputPins) {
  auto chips = station_chips();
  EXPECT_THROW(chips->set_input("NOPE", true), std::invalid_argument);
  EXPECT_EQ(chips->pin_level("NOPE"), std::nullopt);
  GpioSimBank bank(station_config(), chips);
  ASSERT_TRUE(bank.open().ok());
  EXPECT_THROW(chips->set_input("GYRO_PWR1", true), std::invalid_argument);
}
