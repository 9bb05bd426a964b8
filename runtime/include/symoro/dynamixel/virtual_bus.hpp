// A chain of emulated X-series servos behind a pseudo-terminal, so that the real driver (SerialPort
// + Bus) runs end to end without an arm: open device() as if it were /dev/ttyUSB0.
//
//   VirtualBus bus(crane_x7_servos(), std::make_unique<RotorBackend>(rotors));
//   SerialPort port(bus.device(), 3'000'000);
//
// A thread reads instruction packets from the pty master with the project's Decoder and answers
// as the servos would (Protocol 2.0): ping (also broadcast, every servo in chain order), read,
// write (also broadcast), reboot, sync read (replies in the requested ID order), sync write, bulk
// read; Status Return Level(68) and Return Delay Time(9) are honoured. Each servo has a control
// table with the items of control_table.hpp; writes are checked as the e-manual says:
//   access error     : read-only or undefined bytes, or EEPROM (address < 64) with torque on;
//   data length error: a write that covers part of an item;
//   data range error : a value outside the item's range (Goal Current beyond +-Current Limit(38),
//                      Operating Mode not a defined mode, Torque Enable not 0/1, ...).
// Goal Current drives the backend only with torque on, Operating Mode current (0), no hardware
// error and no tripped Bus Watchdog(98); other modes are not emulated (the motor gets no
// current). The bus watchdog counts the time since the last instruction packet on the bus (to
// any servo), on the backend's clock. The baud rate is stored but
// a pty has none: bytes arrive at once. The backend integrates on the wall clock, or on the
// controller's own clock when given one.
//
// Fault injection, thread-safe, for the next instructions: corrupted CRCs, dropped replies, a
// servo that stops answering (and acting), a hardware error (alert bit 7 in every status packet,
// torque off, as a real servo's shutdown does) and a servo answering under another ID.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "symoro/dynamixel/control_table.hpp"
#include "symoro/dynamixel/decoder.hpp"
#include "symoro/dynamixel/instructions.hpp"
#include "symoro/dynamixel/servo_backend.hpp"

namespace symoro::dynamixel {

// One emulated servo's identity and initial EEPROM values.
struct VirtualServo {
  std::uint8_t id = 1;
  xseries::Model model = xseries::kXm430W350;
  std::uint8_t firmware = 45;       // arbitrary
  std::uint8_t baud_rate = 5;       // Baud Rate(8) value: 5 = 3 Mbps
  std::uint8_t return_delay = 0;    // 2 us units; 0 as a 1 kHz bus needs (factory: 250)
  std::uint8_t operating_mode = 3;  // factory: position control
  std::int32_t current_limit = -1;  // -1: the model's maximum (the factory value)
};

// CRANE-X7: axes 1..8 are IDs 2..9, axis 2 (ID 3) an XM540-W270, the others XM430-W350, 3 Mbps.
std::vector<VirtualServo> crane_x7_servos();

struct VirtualBusStats {
  std::uint64_t instructions = 0;   // instruction packets decoded
  std::uint64_t decode_errors = 0;  // rejected frames from the controller
  std::uint64_t replies = 0;        // status packets sent
  std::uint64_t dropped = 0;
  std::uint64_t corrupted = 0;
};

class VirtualBus {
 public:
  // Servo i of `servos` is joint i of `backend` (sizes must match; IDs distinct, 0..252).
  // `plant_clock`: the time (s) the backend integrates to at each instruction, called on the
  // bus's thread; empty: the wall clock since construction. A test that steps the controller's
  // clock (hardware::SteppedClock) gives that clock's seconds, so the arm moves on the loop's time.
  VirtualBus(std::vector<VirtualServo> servos, std::unique_ptr<ServoBackend> backend,
             std::function<double()> plant_clock = {});
  ~VirtualBus();
  VirtualBus(const VirtualBus&) = delete;
  VirtualBus& operator=(const VirtualBus&) = delete;

  // The pty's slave path, to open with SerialPort.
  const std::string& device() const { return device_; }

  // ---- Faults (take effect from the next status packet / instruction) ----
  // Flips a CRC byte of each of the next `count` status packets (any servo).
  void corrupt_replies(std::size_t count);
  // Withholds the next `count` status packets (the instruction is still carried out).
  void drop_replies(std::size_t count);
  // A dead servo: ignores every instruction until revived.
  void set_dead(std::uint8_t id, bool dead);
  // Sets Hardware Error Status(70) (bits of xseries::hardware_error) and turns torque off; 0
  // clears it (as a Reboot does).
  void set_hardware_error(std::uint8_t id, std::uint8_t bits);
  // The servo answers under `reply_id` (a misconfigured chain); its own ID to undo.
  void set_reply_id(std::uint8_t id, std::uint8_t reply_id);

  // ---- Inspection ----
  // A control-table value (sign-extended for Goal/Present Current and Velocity, Present Position).
  std::int32_t value(std::uint8_t id, xseries::Item item) const;
  VirtualBusStats stats() const;

  static constexpr std::size_t kTableSize = 256;  // up to Present Temperature(146) and beyond

 private:
  struct Servo {
    VirtualServo config;
    std::uint8_t id = 0;        // current ID (writable)
    std::uint8_t reply_id = 0;  // ID put in its status packets
    bool dead = false;
    std::uint8_t table[kTableSize] = {};
  };
  struct Outgoing {
    std::size_t offset, size;
    double delay;  // s after the previous packet (Return Delay Time)
  };

  void run();
  void process(const DecodeEvent& event, double now);
  // The instructions process() answers (p: addressed to `broadcast` or one ID).
  void answer_decode_error(const DecodeEvent& event);
  void answer_ping(const Packet& p, bool broadcast);
  void answer_read(const Packet& p);
  void answer_write(const Packet& p, bool broadcast);
  void answer_reboot(const Packet& p, bool broadcast);
  // Whether `s` answers an instruction that needs status return level `level` (0: ping only;
  // 1: ping and reads; 2: everything, the factory value).
  static bool answers(const Servo& s, int level);
  // A read's reply from `s` when it answers at `level`, or an access error.
  void read_into(Servo& s, std::uint16_t address, std::uint16_t length, int level);
  void reply(Servo& servo, std::uint8_t error, ByteView params);
  ErrorNumber apply_write(Servo& servo, std::uint16_t address, ByteView data);
  void update_command(std::size_t index);
  void refresh_present();
  Servo* find(std::uint8_t id);
  std::size_t index_of(const Servo& servo) const { return static_cast<std::size_t>(&servo - servos_.data()); }
  void send_pending();
  double clock() const;
  // Bus Watchdog(98): a servo with torque on whose limit has passed since the last instruction
  // packet on the bus stops (goal current off, the item -1); the caller holds mutex_.
  void trip_bus_watchdogs(double now);
  bool bus_watchdog_armed() const;

  std::vector<Servo> servos_;
  std::unique_ptr<ServoBackend> backend_;
  int master_ = -1;
  int slave_ = -1;  // held open so that the master never sees a hang-up between driver sessions
  int wake_[2] = {-1, -1};
  std::string device_;
  std::thread thread_;
  std::chrono::steady_clock::time_point start_;
  std::function<double()> plant_clock_;
  double last_instruction_ = 0;  // clock() at the last instruction packet (mutex_)

  mutable std::mutex mutex_;  // servos_, backend_, faults, stats
  std::size_t corrupt_count_ = 0;
  std::size_t drop_count_ = 0;
  VirtualBusStats stats_;

  // Thread-only buffers.
  Decoder decoder_;
  Buffer packet_;
  std::vector<std::uint8_t> out_;
  std::vector<Outgoing> pending_;
  std::vector<std::uint8_t> params_;
};

}  // namespace symoro::dynamixel
