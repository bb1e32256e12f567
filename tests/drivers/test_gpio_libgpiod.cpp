// The libgpiod v1 bank against the real kernel interface: missing/non-GPIO chips give typed
// errors; a chip test runs only on a gpio-sim/gpio-mockup chip or a line named by the user.
#include <gpiod.h>
#include <gtest/gtest.h>
#include <poll.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "drivers/gpio/libgpiod_bank.hpp"

using namespace station::drivers;
using namespace station::drivers::gpio;

namespace {

bool have_gpiochips() {
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/dev", ec))
    if (e.path().filename().string().starts_with("gpiochip")) return true;
  return false;
}

// A free line that is safe to request as an input: STATION_GPIO_TEST_LINE ("gpiochipN:OFFSET"),
// else the first free line on a gpio-sim / gpio-mockup chip. "" when there is none.
std::string safe_test_line() {
  if (const char* env = std::getenv("STATION_GPIO_TEST_LINE")) return env;
  for (unsigned n = 0; n < 64; ++n) {
    ChipHandle chip(gpiod_chip_open_by_number(n));
    if (!chip) continue;
    const std::string label = gpiod_chip_label(chip.get());
    if (!label.starts_with("gpio-sim") && !label.starts_with("gpio-mockup")) continue;
    for (unsigned off = 0; off < gpiod_chip_num_lines(chip.get()); ++off) {
      gpiod_line* line = gpiod_chip_get_line(chip.get(), off);
      if (line != nullptr && !gpiod_line_is_used(line))
        return std::string(gpiod_chip_name(chip.get())) + ":" + std::to_string(off);
    }
  }
  return "";
}

}  // namespace

TEST(LibgpiodBank, MissingChipIsATypedError) {
  LibgpiodBank bank(make_gpio_config({{"interlock", "gpiochip_does_not_exist:0"}}));
  EXPECT_EQ(bank.event_fd(), -1);
  auto r = bank.open();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::disconnected);
  EXPECT_NE(r.error().message.find("/dev/gpiochip_does_not_exist"), std::string::npos)
      << r.error().message;
  EXPECT_NE(r.error().message.find("interlock"), std::string::npos) << r.error().message;
  EXPECT_EQ(bank.event_fd(), -1);
  EXPECT_EQ(bank.read(roles::interlock).error().kind, ErrorKind::disconnected);
  EXPECT_EQ(bank.write(roles::relay(1), true).error().kind, ErrorKind::disconnected);
  EXPECT_EQ(bank.read_events().error().kind, ErrorKind::disconnected);
  EXPECT_TRUE(bank.apply_safe_state().ok());  // nothing requested, nothing to drive
  bank.close();
}

TEST(LibgpiodBank, ADeviceThatIsNotAGpioChipIsATypedError) {
  // /dev/null exists but is no GPIO character device: libgpiod refuses it with ENOTTY.
  LibgpiodBank bank(make_gpio_config({{"estop", "null:0"}}));
  auto r = bank.open();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::io) << r.error().message;  // ENOTTY
  EXPECT_NE(r.error().message.find("/dev/null"), std::string::npos) << r.error().message;
  EXPECT_EQ(bank.event_fd(), -1);
}

TEST(LibgpiodBank, RealChipInputLine) {
  if (!have_gpiochips())
    GTEST_SKIP() << "no /dev/gpiochip* on this machine (kernel has no GPIO devices)";
  const std::string spec = safe_test_line();
  if (spec.empty())
    GTEST_SKIP() << "no gpio-sim/gpio-mockup chip; set STATION_GPIO_TEST_LINE=gpiochipN:OFFSET "
                    "to a free line that may be requested as an input";
  LibgpiodBank bank(make_gpio_config({{"interlock", spec}}));
  auto r = bank.open();
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_GE(bank.event_fd(), 0);
  EXPECT_TRUE(bank.read(roles::interlock).ok());
  EXPECT_EQ(bank.write(roles::interlock, true).error().kind, ErrorKind::range);
  pollfd p{bank.event_fd(), POLLIN, 0};
  EXPECT_GE(::poll(&p, 1, 0), 0);
  EXPECT_TRUE(bank.read_events().ok());  // never blocks, even with nothing pending
  bank.close();
  EXPECT_EQ(bank.event_fd(), -1);
}
