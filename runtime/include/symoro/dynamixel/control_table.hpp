// The X-series (Protocol 2.0) control-table items and units the CRANE-X7 controller uses, for
// XM430-W350 (axes 1, 3..8) and XM540-W270 (axis 2). Checked against the ROBOTIS e-manual:
//   https://emanual.robotis.com/docs/en/dxl/x/xm430-w350/  (control table, Model Number 1,020)
//   https://emanual.robotis.com/docs/en/dxl/x/xm540-w270/  (control table, Model Number 1,120)
// Both models share every address below; they differ in the Current Limit range
// (0..1,193 and 0..2,047). Operating modes, baud rates and hardware error bits: the same pages'
// "Operating Mode(11)", "Baud Rate(8)" and "Shutdown(63)" sections.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace symoro::dynamixel::xseries {

// One control-table item: its address and size in bytes.
struct Item {
  std::uint16_t address;
  std::uint8_t size;
};

// EEPROM area (writable only with torque off).
inline constexpr Item kModelNumber{0, 2};
inline constexpr Item kFirmwareVersion{6, 1};
inline constexpr Item kId{7, 1};
inline constexpr Item kBaudRate{8, 1};
inline constexpr Item kReturnDelayTime{9, 1};  // 2 us per unit, default 250 (500 us)
inline constexpr Item kDriveMode{10, 1};
inline constexpr Item kOperatingMode{11, 1};
inline constexpr Item kCurrentLimit{38, 2};
inline constexpr Item kVelocityLimit{44, 4};
inline constexpr Item kMaxPositionLimit{48, 4};
inline constexpr Item kMinPositionLimit{52, 4};
// RAM area.
inline constexpr Item kTorqueEnable{64, 1};
inline constexpr Item kStatusReturnLevel{68, 1};
inline constexpr Item kHardwareErrorStatus{70, 1};
// Bus Watchdog (firmware 38 and later), signed: 0 off (and clears a trip), 1..127 on with a
// limit of that many 20 ms units between instruction packets while torque is on, -1 tripped:
// the servo stopped and its goal values refuse writes (Data Range Error) until it is cleared.
inline constexpr Item kBusWatchdog{98, 1};
inline constexpr double kBusWatchdogUnit = 0.020;  // s
inline constexpr Item kGoalCurrent{102, 2};        // signed
inline constexpr Item kGoalVelocity{104, 4};
inline constexpr Item kGoalPosition{116, 4};
inline constexpr Item kPresentCurrent{126, 2};   // signed
inline constexpr Item kPresentVelocity{128, 4};  // signed
inline constexpr Item kPresentPosition{132, 4};  // signed
inline constexpr Item kPresentInputVoltage{144, 2};
inline constexpr Item kPresentTemperature{146, 1};
// Present Current, Velocity and Position are contiguous: one Sync Read of 10 bytes per cycle.
inline constexpr Item kPresentCurrentVelocityPosition{126, 10};
static_assert(kPresentCurrent.address + kPresentCurrent.size == kPresentVelocity.address &&
              kPresentVelocity.address + kPresentVelocity.size == kPresentPosition.address &&
              kPresentPosition.address + kPresentPosition.size ==
                  kPresentCurrentVelocityPosition.address + kPresentCurrentVelocityPosition.size);

// Operating Mode(11) values.
enum class OperatingMode : std::uint8_t {
  current = 0,  // the paper's current-command mode
  velocity = 1,
  position = 3,  // factory default
  extended_position = 4,
  current_based_position = 5,
  pwm = 16,
};

// Hardware Error Status(70) bits (same layout as Shutdown(63)); the status packet's alert bit
// says that one of them is set.
namespace hardware_error {
inline constexpr std::uint8_t kInputVoltage = 0x01;
inline constexpr std::uint8_t kOverheating = 0x04;
inline constexpr std::uint8_t kMotorEncoder = 0x08;
inline constexpr std::uint8_t kElectricalShock = 0x10;
inline constexpr std::uint8_t kOverload = 0x20;
}  // namespace hardware_error

struct Model {
  std::uint16_t number;  // Model Number(0)
  const char* name;
  std::uint16_t max_current_limit;  // upper end of Current Limit(38)'s range
};
inline constexpr Model kXm430W350{1020, "XM430-W350", 1193};
inline constexpr Model kXm540W270{1120, "XM540-W270", 2047};
// The model with that Model Number among the two above, or nullptr.
constexpr const Model* find_model(std::uint16_t number) {
  if (number == kXm430W350.number) return &kXm430W350;
  if (number == kXm540W270.number) return &kXm540W270;
  return nullptr;
}

// Baud Rate(8) value -> bit/s (0 for a value the X430/X540 series do not define).
constexpr std::uint32_t baud_rate_bps(std::uint8_t value) {
  constexpr std::uint32_t kRates[] = {9'600, 57'600, 115'200, 1'000'000, 2'000'000, 3'000'000, 4'000'000, 4'500'000};
  return value < 8 ? kRates[value] : 0;
}

// ---- Units --------------------------------------------------------------------------------------
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kCurrentUnit = 2.69e-3;                            // A per unit ("about 2.69 mA")
inline constexpr double kVelocityUnit = 0.229 * 2.0 * kPi / 60;            // rad/s per unit (0.229 rev/min)
inline constexpr std::int32_t kPulsesPerRevolution = 4096;                 // 0..4,095 per turn, CCW positive
inline constexpr double kPositionUnit = 2.0 * kPi / kPulsesPerRevolution;  // rad per pulse
// The pulse count taken as 0 rad: the middle of 0..4,095. The e-manual defines no angle origin;
// this is the convention of CRANE-X7's drivers, to be confirmed per joint when homing.
inline constexpr std::int32_t kCenterPosition = 2048;
inline constexpr double kReturnDelayUnit = 2e-6;  // s per unit of Return Delay Time(9)

constexpr double current_to_amps(std::int16_t raw) { return raw * kCurrentUnit; }
// Nearest Goal Current value, saturated to +-limit (pass the servo's Current Limit); NaN gives 0
// so that a failed computation never commands current.
inline std::int16_t amps_to_current(double amps, std::int16_t limit = 32767) {
  const double bound = limit < 0 ? 0.0 : static_cast<double>(limit);
  const double raw = std::round(amps / kCurrentUnit);
  if (std::isnan(raw)) return 0;
  return static_cast<std::int16_t>(std::clamp(raw, -bound, bound));
}
constexpr double velocity_to_rad_s(std::int32_t raw) { return raw * kVelocityUnit; }
constexpr double position_to_rad(std::int32_t raw, std::int32_t zero = kCenterPosition) {
  return (static_cast<double>(raw) - zero) * kPositionUnit;
}
// Nearest pulse count (saturated to the int32 range).
inline std::int32_t rad_to_position(double rad, std::int32_t zero = kCenterPosition) {
  const double raw = std::round(rad / kPositionUnit) + zero;
  if (std::isnan(raw)) return zero;
  if (raw >= 2147483647.0) return std::numeric_limits<std::int32_t>::max();
  if (raw <= -2147483648.0) return std::numeric_limits<std::int32_t>::min();
  return static_cast<std::int32_t>(raw);
}

}  // namespace symoro::dynamixel::xseries
