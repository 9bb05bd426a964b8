#include "symoro/dynamixel/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <utility>

#if defined(__linux__)
#include <linux/serial.h>
#endif

namespace symoro::dynamixel {
namespace {

struct Rate {
  std::uint32_t bps;
  speed_t code;
};

// The termios rates a DYNAMIXEL bus can use (X series: 9,600 bps to 4.5 Mbps; 4.5 Mbps has no
// termios constant). The fast ones are platform extensions, hence the guards.
constexpr Rate kRates[] = {
    {9'600, B9600},        {19'200, B19200}, {38'400, B38400}, {57'600, B57600}, {115'200, B115200}, {230'400, B230400},
#ifdef B460800
    {460'800, B460800},
#endif
#ifdef B500000
    {500'000, B500000},
#endif
#ifdef B576000
    {576'000, B576000},
#endif
#ifdef B921600
    {921'600, B921600},
#endif
#ifdef B1000000
    {1'000'000, B1000000},
#endif
#ifdef B1152000
    {1'152'000, B1152000},
#endif
#ifdef B1500000
    {1'500'000, B1500000},
#endif
#ifdef B2000000
    {2'000'000, B2000000},
#endif
#ifdef B2500000
    {2'500'000, B2500000},
#endif
#ifdef B3000000
    {3'000'000, B3000000},
#endif
#ifdef B3500000
    {3'500'000, B3500000},
#endif
#ifdef B4000000
    {4'000'000, B4000000},
#endif
};

const Rate* find_rate(std::uint32_t bps) {
  for (const Rate& r : kRates)
    if (r.bps == bps) return &r;
  return nullptr;
}

// Waits with poll() for `events` on `fd` until `deadline` (ppoll where available: microsecond
// resolution, where poll()'s milliseconds would overshoot a sub-millisecond deadline). Returns
// the revents, 0 at the deadline; EINTR counts as a spurious wake-up (0 before the deadline).
int wait_for(int fd, short events, SerialPort::Clock::time_point deadline, int& error) {
  auto left = deadline - SerialPort::Clock::now();
  if (left < SerialPort::Clock::duration::zero()) left = SerialPort::Clock::duration::zero();
  pollfd p{fd, events, 0};
#if defined(__linux__)
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
  const timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  const int r = ::ppoll(&p, 1, &ts, nullptr);
#else
  const auto ms = std::chrono::ceil<std::chrono::milliseconds>(left).count();
  const int r = ::poll(&p, 1, ms > 1'000'000 ? 1'000'000 : static_cast<int>(ms));
#endif
  error = 0;
  if (r < 0) {
    if (errno != EINTR) error = errno;
    return 0;
  }
  return r == 0 ? 0 : (p.revents == 0 ? 0 : p.revents);
}

}  // namespace

SerialPort::SerialPort(const std::string& device, std::uint32_t baud) { open(device, baud); }

SerialPort::~SerialPort() { close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), device_(std::move(other.device_)), baud_(other.baud_) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    device_ = std::move(other.device_);
    baud_ = other.baud_;
  }
  return *this;
}

void SerialPort::fail(const char* what, int error) const {
  throw SerialError(error, std::generic_category(), "serial port " + device_ + ": " + what);
}

bool SerialPort::is_supported_baud(std::uint32_t baud) { return find_rate(baud) != nullptr; }

void SerialPort::open(const std::string& device, std::uint32_t baud) {
  close();
  device_ = device;
  if (!is_supported_baud(baud))  // before touching the device: nothing to undo
    throw std::invalid_argument("serial port " + device + ": baud rate " + std::to_string(baud) +
                                " bit/s is not a termios rate of this platform");
  fd_ = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) fail("open", errno);
  try {
    if (::ioctl(fd_, TIOCEXCL) != 0) fail("TIOCEXCL", errno);
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) fail("tcgetattr", errno);
    ::cfmakeraw(&tio);
    tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS | CSIZE);
    tio.c_cflag |= CS8 | CLOCAL | CREAD;
    tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    tio.c_cc[VMIN] = 0;  // reads never block (O_NONBLOCK too); poll() does the waiting
    tio.c_cc[VTIME] = 0;
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) fail("tcsetattr", errno);
    set_baud(baud);
#if defined(__linux__) && defined(ASYNC_LOW_LATENCY)
    // Best effort: only USB-serial and UART drivers know it (a pty refuses; that is fine).
    serial_struct ss{};
    if (::ioctl(fd_, TIOCGSERIAL, &ss) == 0) {
      ss.flags |= ASYNC_LOW_LATENCY;
      (void)::ioctl(fd_, TIOCSSERIAL, &ss);
    }
#endif
    ::tcflush(fd_, TCIOFLUSH);
  } catch (...) {
    close();
    throw;
  }
}

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void SerialPort::set_baud(std::uint32_t baud) {
  const Rate* rate = find_rate(baud);
  if (!rate)
    throw std::invalid_argument("serial port " + device_ + ": baud rate " + std::to_string(baud) +
                                " bit/s is not a termios rate of this platform");
  if (fd_ < 0) fail("set baud rate", EBADF);
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) fail("tcgetattr", errno);
  if (::cfsetispeed(&tio, rate->code) != 0 || ::cfsetospeed(&tio, rate->code) != 0) fail("cfsetspeed", errno);
  if (::tcsetattr(fd_, TCSANOW, &tio) != 0) fail("tcsetattr (baud rate)", errno);
  baud_ = baud;
}

bool SerialPort::write_all(ByteView bytes, Clock::time_point deadline) {
  if (fd_ < 0) fail("write", EBADF);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) fail("write", errno);
    // Output buffer full: wait for room, but not past the deadline.
    if (SerialPort::Clock::now() >= deadline) return false;
    int error = 0;
    const int revents = wait_for(fd_, POLLOUT, deadline, error);
    if (error) fail("poll (write)", error);
    if (revents & (POLLERR | POLLNVAL | POLLHUP)) fail("write (device error or hang-up)", EIO);
  }
  return true;
}

std::size_t SerialPort::read_some(Span<std::uint8_t> buffer, Clock::time_point deadline) {
  if (fd_ < 0) fail("read", EBADF);
  if (buffer.empty()) return 0;
  for (;;) {
    const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
    if (n > 0) return static_cast<std::size_t>(n);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) fail("read", errno);
    // n == 0 on a tty with VMIN = 0 also means "nothing yet".
    if (Clock::now() >= deadline) return 0;
    int error = 0;
    const int revents = wait_for(fd_, POLLIN, deadline, error);
    if (error) fail("poll (read)", error);
    if (revents & POLLNVAL) fail("read (poll)", EBADF);
    if (!(revents & POLLIN) && (revents & (POLLERR | POLLHUP)))
      fail("read (device hung up)", EIO);  // adapter unplugged, pty master closed
  }
}

void SerialPort::flush_input() {
  if (fd_ >= 0 && ::tcflush(fd_, TCIFLUSH) != 0) fail("tcflush", errno);
}

SerialPort::Clock::duration SerialPort::transmit_time(std::size_t bytes) const {
  if (baud_ == 0) return Clock::duration::zero();
  const double seconds = 10.0 * static_cast<double>(bytes) / baud_;
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace symoro::dynamixel
