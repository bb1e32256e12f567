// The station's discrete I/O interface (interlock, e-stop, relays, tower light) and its line
// configuration. No libgpiod here: the simulator implements this header, the real bank is in
// libgpiod_bank.hpp.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/common/result.hpp"
#include "drivers/common/tap.hpp"

namespace station::drivers::gpio {

/// Well-known line roles (the keys of the config's line map).
namespace roles {
/// Input, active = door interlock made (door closed); an opening door is a falling edge.
inline constexpr std::string_view interlock = "interlock";
/// Input, active = emergency stop pressed.
inline constexpr std::string_view estop = "estop";
/// Output, active = tower lamp lit; safe default off.
inline constexpr std::string_view tower_green = "tower.green";
/// Output, active = tower lamp lit; safe default off.
inline constexpr std::string_view tower_amber = "tower.amber";
/// Output, active = tower lamp lit; safe default ON (red until the station says otherwise).
inline constexpr std::string_view tower_red = "tower.red";
/// Output role name of the gyro power relay for slot 1..99 ("relay.3"); safe default off.
std::string relay(int slot);
}  // namespace roles

/// Whether the station reads or drives a line.
enum class GpioDirection { input, output };

/// One configured line: which role it plays, where it is, and how it is wired.
struct GpioLineConfig {
  std::string role;       ///< "interlock", "estop", "relay.N", "tower.green|amber|red"
  std::string chip;       ///< chip device name under /dev, e.g. "gpiochip0"
  std::string line_name;  ///< line name resolved by gpiod_chip_find_line ("" = use offset)
  int offset = -1;        ///< line offset on the chip when line_name is empty
  GpioDirection direction = GpioDirection::input;
  bool active_low = false;  ///< logical active = electrical low
  bool safe_level = false;  ///< outputs: logical level at request, on safe state and release
  /// "DOOR_SW" or "gpiochip0:17", for errors and tap records.
  std::string where() const;
};

/// Every line of one station's bank.
struct GpioConfig {
  std::string consumer = "gyro-station";  ///< consumer label the kernel shows for our lines
  std::vector<GpioLineConfig> lines;
};

/// Builds a config from {role: spec}. spec = ["!"] [CHIP ":"] (LINE_NAME | OFFSET); "!" marks
/// active-low; CHIP defaults to default_chip. Direction and safe level follow from the role.
/// Throws std::invalid_argument naming the key on an unknown role or malformed spec (config).
GpioConfig make_gpio_config(const std::map<std::string, std::string>& line_map,
                            const std::string& default_chip = "gpiochip0");

/// Parses one spec into chip/line_name/offset/active_low of `line` (role untouched); throws
/// std::invalid_argument naming the spec when malformed.
void parse_line_spec(std::string_view spec, const std::string& default_chip, GpioLineConfig& line);

/// One edge on an input line, in logical levels (active-low already applied).
struct GpioEdge {
  std::string role;          ///< "interlock", "estop", ...
  std::string line;          ///< where the line is ("DOOR_SW" or "gpiochip0:17")
  bool rising = false;       ///< true: became active; false: became inactive
  double timestamp_s = 0.0;  ///< CLOCK_MONOTONIC seconds (kernel edge stamp on real chips)
};

/// A bank of discrete I/O lines. The constructor does no I/O; no call blocks.
class GpioBank {
 public:
  virtual ~GpioBank() = default;
  /// Requests every configured line; outputs start at their safe level. Errors name the line.
  virtual Result<void> open() = 0;
  /// Logical level of a line by role (inputs: sampled now; outputs: the level driven).
  virtual Result<bool> read(std::string_view role) = 0;
  /// Drives an output by role to a logical level. ErrorKind::range for inputs/unknown roles.
  virtual Result<void> write(std::string_view role, bool active) = 0;
  /// Drives every output to its safe level; tries all lines, returns the first error.
  virtual Result<void> apply_safe_state() = 0;
  /// Safe state, then releases all lines. Idempotent; the destructor calls it.
  virtual void close() = 0;
  /// One fd that becomes readable (poll POLLIN) when edges are pending; -1 when not open.
  virtual int event_fd() const = 0;
  /// Drains pending edges in arrival order; empty when none. Never blocks.
  virtual Result<std::vector<GpioEdge>> read_events() = 0;
  /// Sets the tap every edge and write passes (nullptr: none). Not owned.
  virtual void set_tap(Tap* tap) = 0;
  /// The configuration the bank was built with.
  virtual const GpioConfig& config() const = 0;
};

/// Finds the configured line with this role; nullptr if none.
const GpioLineConfig* find_role(const GpioConfig& config, std::string_view role);

/// Tap record for an edge (direction event, kind "gpio-edge", bytes {level}).
TapRecord gpio_edge_record(const std::string& device, const GpioEdge& edge);
/// Tap record for a read (direction rx, kind "gpio-read", bytes {logical level}).
TapRecord gpio_read_record(const std::string& device, const GpioLineConfig& line, bool active);
/// Tap record for a write (direction tx, kind "gpio-write", bytes {level}).
TapRecord gpio_write_record(const std::string& device, const GpioLineConfig& line, bool active);

}  // namespace station::drivers::gpio
