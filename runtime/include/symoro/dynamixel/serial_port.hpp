// A POSIX serial port for a DYNAMIXEL bus (a U2D2 or any USB-RS485 adapter, or a pseudo-terminal):
// raw 8N1, no flow control, non-blocking I/O waited on with poll() against steady_clock deadlines,
// so that a silent or broken bus can never hold the caller beyond the deadline it gave.
//
//   SerialPort port("/dev/ttyUSB0", 3'000'000);
//   port.write_all(packet, SerialPort::Clock::now() + 1ms);
//   std::size_t n = port.read_some(buffer, deadline);  // 0: nothing arrived before the deadline
//
// Errors throw SerialError, whose message names the device and the errno text.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <system_error>

#include "symoro/dynamixel/span.hpp"

namespace symoro::dynamixel {

class SerialError : public std::system_error {
 public:
  using std::system_error::system_error;
};

class SerialPort {
 public:
  using Clock = std::chrono::steady_clock;

  SerialPort() = default;
  // Opens `device` at `baud` bit/s (see open()).
  SerialPort(const std::string& device, std::uint32_t baud);
  ~SerialPort();
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Opens the device in raw 8N1 mode, exclusive (TIOCEXCL: a second driver on the same bus would
  // interleave packets), and asks the driver for low latency where it can (FTDI adapters such as
  // the U2D2 otherwise hold received bytes up to 16 ms). Closes a port already open.
  void open(const std::string& device, std::uint32_t baud);
  void close();
  bool is_open() const { return fd_ >= 0; }
  const std::string& device() const { return device_; }
  std::uint32_t baud() const { return baud_; }
  int native_handle() const { return fd_; }

  // Standard termios rates only (up to 4 Mbps where the platform defines B4000000); another
  // rate throws std::invalid_argument naming the device and the rate. A pty accepts any of them
  // and ignores it.
  void set_baud(std::uint32_t baud);
  static bool is_supported_baud(std::uint32_t baud);

  // Writes every byte unless the deadline passes first; returns whether all were written.
  bool write_all(ByteView bytes, Clock::time_point deadline);
  // Waits until bytes are available or the deadline passes, then returns what arrived (up to
  // buffer.size()); 0 means nothing arrived before the deadline. A deadline already past still
  // takes what is waiting.
  std::size_t read_some(Span<std::uint8_t> buffer, Clock::time_point deadline);
  // Discards received bytes not read yet (a late reply to a timed-out request).
  void flush_input();

  // Wire time of `bytes` bytes at the current rate (10 bits per byte: start, 8 data, stop).
  Clock::duration transmit_time(std::size_t bytes) const;

 private:
  [[noreturn]] void fail(const char* what, int error) const;

  int fd_ = -1;
  std::string device_;
  std::uint32_t baud_ = 0;
};

}  // namespace symoro::dynamixel
