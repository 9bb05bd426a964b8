#include "symoro/dynamixel/virtual_bus.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include "symoro/dynamixel/endian.hpp"

namespace symoro::dynamixel {
namespace {

namespace xs = xseries;

// How a written value is checked.
enum class Check : std::uint8_t {
  read_only,
  range,           // [min, max]
  operating_mode,  // one of the defined modes
  current_limit,   // 0..the model's maximum
  goal_current,    // +-Current Limit(38)
  goal_velocity,   // +-Velocity Limit(44)
  goal_position,   // Min..Max Position Limit(52, 48)
};

struct Rule {
  xs::Item item;
  Check check;
  bool is_signed;
  std::int32_t min, max;
};

// The control-table items the emulation defines (control_table.hpp); other bytes are undefined.
constexpr Rule kRules[] = {
    {xs::kModelNumber, Check::read_only, false, 0, 0},
    {xs::kFirmwareVersion, Check::read_only, false, 0, 0},
    {xs::kId, Check::range, false, 0, kMaxId},
    {xs::kBaudRate, Check::range, false, 0, 7},
    {xs::kReturnDelayTime, Check::range, false, 0, 254},
    {xs::kDriveMode, Check::range, false, 0, 13},
    {xs::kOperatingMode, Check::operating_mode, false, 0, 0},
    {xs::kCurrentLimit, Check::current_limit, false, 0, 0},
    {xs::kVelocityLimit, Check::range, false, 0, 1023},
    {xs::kMaxPositionLimit, Check::range, false, 0, 4095},
    {xs::kMinPositionLimit, Check::range, false, 0, 4095},
    {xs::kTorqueEnable, Check::range, false, 0, 1},
    {xs::kStatusReturnLevel, Check::range, false, 0, 2},
    {xs::kHardwareErrorStatus, Check::read_only, false, 0, 0},
    {xs::kBusWatchdog, Check::range, true, 0, 127},
    {xs::kGoalCurrent, Check::goal_current, true, 0, 0},
    {xs::kGoalVelocity, Check::goal_velocity, true, 0, 0},
    {xs::kGoalPosition, Check::goal_position, false, 0, 0},
    {xs::kPresentCurrent, Check::read_only, true, 0, 0},
    {xs::kPresentVelocity, Check::read_only, true, 0, 0},
    {xs::kPresentPosition, Check::read_only, true, 0, 0},
    {xs::kPresentInputVoltage, Check::read_only, false, 0, 0},
    {xs::kPresentTemperature, Check::read_only, false, 0, 0},
};
constexpr std::uint16_t kRamStart = xs::kTorqueEnable.address;  // below: EEPROM

const Rule* rule_at(std::size_t address) {
  for (const Rule& r : kRules)
    if (address >= r.item.address && address < r.item.address + r.item.size) return &r;
  return nullptr;
}

std::int32_t get(const std::uint8_t* table, xs::Item item, bool is_signed) {
  return is_signed ? load_le_signed(table + item.address, item.size)
                   : static_cast<std::int32_t>(load_le_unsigned(table + item.address, item.size));
}

void put(std::uint8_t* table, xs::Item item, std::int32_t value) {
  std::uint8_t bytes[4];
  store_le(bytes, value);
  std::copy(bytes, bytes + item.size, table + item.address);
}

bool is_operating_mode(std::int32_t v) { return v == 0 || v == 1 || v == 3 || v == 4 || v == 5 || v == 16; }

[[noreturn]] void fail(const char* what) {
  throw std::system_error(errno, std::generic_category(), std::string("virtual bus: ") + what);
}

}  // namespace

std::vector<VirtualServo> crane_x7_servos() {
  std::vector<VirtualServo> servos;
  for (std::uint8_t id = 2; id <= 9; ++id) {
    VirtualServo s;
    s.id = id;
    s.model = id == 3 ? xs::kXm540W270 : xs::kXm430W350;
    servos.push_back(s);
  }
  return servos;
}

VirtualBus::VirtualBus(std::vector<VirtualServo> servos, std::unique_ptr<ServoBackend> backend,
                       std::function<double()> plant_clock)
    : backend_(std::move(backend)), plant_clock_(std::move(plant_clock)) {
  if (!backend_ || backend_->size() != servos.size())
    throw std::invalid_argument("virtual bus: the backend must have one joint per servo");
  servos_.resize(servos.size());
  for (std::size_t i = 0; i < servos.size(); ++i) {
    const VirtualServo& c = servos[i];
    if (c.id > kMaxId) throw std::invalid_argument("virtual bus: servo ID above 252");
    for (std::size_t j = 0; j < i; ++j)
      if (servos[j].id == c.id) throw std::invalid_argument("virtual bus: duplicate servo ID");
    Servo& s = servos_[i];
    s.config = c;
    s.id = s.reply_id = c.id;
    std::uint8_t* t = s.table;
    put(t, xs::kModelNumber, c.model.number);
    put(t, xs::kFirmwareVersion, c.firmware);
    put(t, xs::kId, c.id);
    put(t, xs::kBaudRate, c.baud_rate);
    put(t, xs::kReturnDelayTime, c.return_delay);
    put(t, xs::kOperatingMode, c.operating_mode);
    put(t, xs::kCurrentLimit, c.current_limit < 0 ? c.model.max_current_limit : c.current_limit);
    put(t, xs::kVelocityLimit, 200);  // not enforced beyond Goal Velocity's range
    put(t, xs::kMaxPositionLimit, 4095);
    put(t, xs::kMinPositionLimit, 0);
    put(t, xs::kStatusReturnLevel, 2);
    put(t, xs::kPresentInputVoltage, 120);  // 12.0 V
    put(t, xs::kPresentTemperature, 35);
  }
  packet_.reserve(256);
  out_.reserve(4096);
  params_.reserve(kTableSize);

  // The pty: the master is the servos' end of the cable; the slave is what the driver opens.
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master_ < 0) fail("posix_openpt");
  try {
    if (::grantpt(master_) != 0) fail("grantpt");
    if (::unlockpt(master_) != 0) fail("unlockpt");
    char name[128];
    if (::ptsname_r(master_, name, sizeof name) != 0) fail("ptsname_r");
    device_ = name;
    ::fcntl(master_, F_SETFD, FD_CLOEXEC);
    ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
    slave_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (slave_ < 0) fail("open pty slave");
    termios tio{};  // raw from the start: no echo or line editing even before the driver opens it
    if (::tcgetattr(slave_, &tio) != 0) fail("tcgetattr");
    ::cfmakeraw(&tio);
    if (::tcsetattr(slave_, TCSANOW, &tio) != 0) fail("tcsetattr");
    if (::pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0) fail("pipe2");
  } catch (...) {
    for (int fd : {master_, slave_, wake_[0], wake_[1]})
      if (fd >= 0) ::close(fd);
    throw;
  }
  start_ = std::chrono::steady_clock::now();
  backend_->advance(clock());
  thread_ = std::thread([this] { run(); });
}

VirtualBus::~VirtualBus() {
  const char byte = 0;
  (void)!::write(wake_[1], &byte, 1);
  if (thread_.joinable()) thread_.join();
  for (int fd : {master_, slave_, wake_[0], wake_[1]})
    if (fd >= 0) ::close(fd);
}

double VirtualBus::clock() const {
  if (plant_clock_) return plant_clock_();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

VirtualBus::Servo* VirtualBus::find(std::uint8_t id) {
  for (Servo& s : servos_)
    if (s.id == id) return &s;
  return nullptr;
}

void VirtualBus::corrupt_replies(std::size_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  corrupt_count_ = count;
}

void VirtualBus::drop_replies(std::size_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  drop_count_ = count;
}

void VirtualBus::set_dead(std::uint8_t id, bool dead) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (Servo* s = find(id)) s->dead = dead;
}

void VirtualBus::set_hardware_error(std::uint8_t id, std::uint8_t bits) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (Servo* s = find(id)) {
    put(s->table, xs::kHardwareErrorStatus, bits);
    if (bits) put(s->table, xs::kTorqueEnable, 0);  // the shutdown a real servo performs
    backend_->advance(clock());
    update_command(index_of(*s));
  }
}

void VirtualBus::set_reply_id(std::uint8_t id, std::uint8_t reply_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (Servo* s = find(id)) s->reply_id = reply_id;
}

std::int32_t VirtualBus::value(std::uint8_t id, xseries::Item item) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Servo& s : servos_)
    if (s.id == id) {
      const Rule* rule = rule_at(item.address);
      return get(s.table, item, rule && rule->is_signed);
    }
  throw std::invalid_argument("virtual bus: no servo with ID " + std::to_string(id));
}

VirtualBusStats VirtualBus::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void VirtualBus::update_command(std::size_t index) {
  const std::uint8_t* t = servos_[index].table;
  const bool drive = get(t, xs::kTorqueEnable, false) == 1 &&
                     get(t, xs::kOperatingMode, false) == static_cast<std::int32_t>(xs::OperatingMode::current) &&
                     get(t, xs::kHardwareErrorStatus, false) == 0 && get(t, xs::kBusWatchdog, true) != -1;
  const double amps = drive ? get(t, xs::kGoalCurrent, true) * xs::kCurrentUnit : 0.0;
  backend_->set_current(index, amps);
}

void VirtualBus::refresh_present() {
  for (std::size_t i = 0; i < servos_.size(); ++i) {
    const JointState st = backend_->state(i);
    std::uint8_t* t = servos_[i].table;
    const double current = std::clamp(std::round(st.current / xs::kCurrentUnit), -32768.0, 32767.0);
    const double velocity = std::clamp(std::round(st.velocity / xs::kVelocityUnit), -2147483648.0, 2147483647.0);
    put(t, xs::kPresentCurrent, static_cast<std::int32_t>(current));
    put(t, xs::kPresentVelocity, static_cast<std::int32_t>(velocity));
    put(t, xs::kPresentPosition, xs::rad_to_position(st.position));
  }
}

ErrorNumber VirtualBus::apply_write(Servo& servo, std::uint16_t address, ByteView data) {
  if (data.empty()) return ErrorNumber::data_length_error;
  const std::size_t end = std::size_t{address} + data.size();
  if (end > kTableSize) return ErrorNumber::access_error;
  std::uint8_t* t = servo.table;
  const bool torque = get(t, xs::kTorqueEnable, false) == 1;
  // Check every item the write covers before changing anything: a refused write has no effect.
  for (std::size_t a = address; a < end;) {
    const Rule* r = rule_at(a);
    if (!r || r->check == Check::read_only) return ErrorNumber::access_error;
    if (r->item.address != a || r->item.address + r->item.size > end)
      return ErrorNumber::data_length_error;                        // part of a multi-byte item
    if (a < kRamStart && torque) return ErrorNumber::access_error;  // EEPROM is locked
    const std::uint8_t* p = data.data() + (a - address);
    const std::int32_t v =
        r->is_signed ? load_le_signed(p, r->item.size) : static_cast<std::int32_t>(load_le_unsigned(p, r->item.size));
    bool in_range = true;
    // A tripped bus watchdog makes the goal values read-only: writes get a Data Range Error.
    const bool goal =
        r->check == Check::goal_current || r->check == Check::goal_velocity || r->check == Check::goal_position;
    if (goal && get(t, xs::kBusWatchdog, true) == -1) return ErrorNumber::data_range_error;
    switch (r->check) {
      case Check::range:
        in_range = v >= r->min && v <= r->max;
        break;
      case Check::operating_mode:
        in_range = is_operating_mode(v);
        break;
      case Check::current_limit:
        in_range = v >= 0 && v <= servo.config.model.max_current_limit;
        break;
      case Check::goal_current: {
        const std::int32_t limit = get(t, xs::kCurrentLimit, false);
        in_range = v >= -limit && v <= limit;
        break;
      }
      case Check::goal_velocity: {
        const std::int32_t limit = get(t, xs::kVelocityLimit, false);
        in_range = v >= -limit && v <= limit;
        break;
      }
      case Check::goal_position:
        in_range = v >= get(t, xs::kMinPositionLimit, false) && v <= get(t, xs::kMaxPositionLimit, false);
        break;
      case Check::read_only:
        break;
    }
    if (!in_range) return ErrorNumber::data_range_error;
    a += r->item.size;
  }
  const std::uint8_t old_id = servo.id;
  std::copy(data.begin(), data.end(), t + address);
  // A servo with a hardware error keeps its torque off until rebooted.
  if (get(t, xs::kHardwareErrorStatus, false) != 0) put(t, xs::kTorqueEnable, 0);
  servo.id = static_cast<std::uint8_t>(get(t, xs::kId, false));
  if (servo.reply_id == old_id) servo.reply_id = servo.id;
  update_command(index_of(servo));
  return ErrorNumber::none;
}

void VirtualBus::reply(Servo& servo, std::uint8_t error, ByteView params) {
  if (get(servo.table, xs::kHardwareErrorStatus, false) != 0) error |= 0x80;
  encode_status(servo.reply_id, error, params, packet_);
  if (drop_count_ > 0) {
    --drop_count_;
    ++stats_.dropped;
    return;
  }
  if (corrupt_count_ > 0) {
    --corrupt_count_;
    ++stats_.corrupted;
    packet_[packet_.size() - 2] ^= 0x01;  // CRC low byte
    // A last byte of FF would look like the start of a next header and make the decoder wait
    // for more bytes; a real corruption could, but the test wants a prompt CRC error.
    if (packet_.back() == 0xFF) packet_.back() = 0xFE;
  }
  ++stats_.replies;
  pending_.push_back(
      Outgoing{out_.size(), packet_.size(), get(servo.table, xs::kReturnDelayTime, false) * xs::kReturnDelayUnit});
  out_.insert(out_.end(), packet_.begin(), packet_.end());
}

bool VirtualBus::answers(const Servo& s, int level) {
  return !s.dead && get(s.table, xs::kStatusReturnLevel, false) >= level;
}

void VirtualBus::read_into(Servo& s, std::uint16_t address, std::uint16_t length, int level) {
  if (!answers(s, level)) return;
  if (std::size_t{address} + length > kTableSize) {
    reply(s, static_cast<std::uint8_t>(ErrorNumber::access_error), ByteView());
    return;
  }
  reply(s, 0, ByteView(s.table + address, length));
}

// A unicast instruction whose CRC failed gets the CRC error status.
void VirtualBus::answer_decode_error(const DecodeEvent& event) {
  ++stats_.decode_errors;
  if (event.error == DecodeError::bad_crc && event.raw.size() > 4)
    if (Servo* s = find(event.raw[4]); s && !s->dead && get(s->table, xs::kStatusReturnLevel, false) == 2)
      reply(*s, static_cast<std::uint8_t>(ErrorNumber::crc_error), ByteView());
}

void VirtualBus::answer_ping(const Packet& p, bool broadcast) {
  for (Servo& s : servos_)
    if ((broadcast || s.id == p.id) && answers(s, 0)) {
      std::uint8_t params[3];
      store_le<std::uint16_t>(params, static_cast<std::uint16_t>(get(s.table, xs::kModelNumber, false)));
      params[2] = s.table[xs::kFirmwareVersion.address];
      reply(s, 0, ByteView(params, 3));
    }
}

void VirtualBus::answer_read(const Packet& p) {
  Servo* s = p.id == kBroadcastId ? nullptr : find(p.id);
  if (!s) return;
  const auto r = parse_read(p);
  if (!r) {
    if (answers(*s, 1)) reply(*s, static_cast<std::uint8_t>(ErrorNumber::data_length_error), ByteView());
    return;
  }
  refresh_present();
  read_into(*s, r->address, r->length, 1);
}

void VirtualBus::answer_write(const Packet& p, bool broadcast) {
  const auto w = parse_write(p);
  for (Servo& s : servos_) {
    if (s.dead || !(broadcast || s.id == p.id)) continue;
    const std::uint8_t old_reply_id = s.reply_id;
    const ErrorNumber e = w ? apply_write(s, w->address, w->data) : ErrorNumber::data_length_error;
    if (!broadcast && get(s.table, xs::kStatusReturnLevel, false) == 2) {
      const std::uint8_t now_reply_id = s.reply_id;
      s.reply_id = old_reply_id;  // the status of an ID change comes from the old ID
      reply(s, static_cast<std::uint8_t>(e), ByteView());
      s.reply_id = now_reply_id;
    }
    if (!broadcast) break;
  }
}

void VirtualBus::answer_reboot(const Packet& p, bool broadcast) {
  for (Servo& s : servos_)
    if (!s.dead && (broadcast || s.id == p.id)) {
      put(s.table, xs::kHardwareErrorStatus, 0);
      put(s.table, xs::kTorqueEnable, 0);
      put(s.table, xs::kGoalCurrent, 0);
      update_command(index_of(s));
      if (!broadcast && answers(s, 2)) reply(s, 0, ByteView());
    }
}

void VirtualBus::process(const DecodeEvent& event, double now) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (event.kind == DecodeEvent::Kind::error) {
    answer_decode_error(event);
    return;
  }
  const Packet& p = event.packet;
  if (p.is_status()) return;  // another device's status: not for the servos
  ++stats_.instructions;
  trip_bus_watchdogs(now);  // a silence that ended with this packet may have tripped them first
  last_instruction_ = now;
  backend_->advance(now);
  const bool broadcast = p.id == kBroadcastId;
  switch (p.instruction) {
    case Instruction::ping:
      answer_ping(p, broadcast);
      break;
    case Instruction::read:
      answer_read(p);
      break;
    case Instruction::write:
      answer_write(p, broadcast);
      break;
    case Instruction::reboot:
      answer_reboot(p, broadcast);
      break;
    case Instruction::sync_read:
      if (const auto r = parse_sync_read(p); r && broadcast) {
        refresh_present();
        for (std::uint8_t id : r->ids)  // in the requested order
          if (Servo* s = find(id)) read_into(*s, r->address, r->length, 1);
      }
      break;
    case Instruction::sync_write:
      if (const auto r = parse_sync_write(p); r && broadcast)
        for (std::size_t i = 0; i < r->count(); ++i)
          if (Servo* s = find(r->id(i)); s && !s->dead) (void)apply_write(*s, r->address, r->data(i));
      break;
    case Instruction::bulk_read:
      if (const auto r = parse_bulk_read(p); r && broadcast) {
        refresh_present();
        for (std::size_t i = 0; i < r->count(); ++i) {
          const BulkReadItem item = r->item(i);
          if (Servo* s = find(item.id)) read_into(*s, item.address, item.length, 1);
        }
      }
      break;
    default:  // Reg Write, Action, Factory Reset, Clear, Bulk Write: not emulated
      if (!broadcast)
        if (Servo* s = find(p.id); s && answers(*s, 2))
          reply(*s, static_cast<std::uint8_t>(ErrorNumber::instruction_error), ByteView());
      break;
  }
}

void VirtualBus::send_pending() {
  auto write_out = [this](const std::uint8_t* data, std::size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(master_, data, size);
      if (n > 0) {
        data += n;
        size -= static_cast<std::size_t>(n);
      } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
        pollfd p{master_, POLLOUT, 0};
        ::poll(&p, 1, 10);
      } else {
        return;  // the driver's side is gone: drop the reply, as a cut cable would
      }
    }
  };
  std::size_t sent = 0;  // bytes of out_ written
  for (const Outgoing& o : pending_) {
    if (o.delay > 0) {  // Return Delay Time: send what precedes, then wait
      write_out(out_.data() + sent, o.offset - sent);
      sent = o.offset;
      std::this_thread::sleep_for(std::chrono::duration<double>(o.delay));
    }
  }
  write_out(out_.data() + sent, out_.size() - sent);
  out_.clear();
  pending_.clear();
}

void VirtualBus::trip_bus_watchdogs(double now) {
  for (std::size_t i = 0; i < servos_.size(); ++i) {
    std::uint8_t* t = servos_[i].table;
    const std::int32_t limit = get(t, xs::kBusWatchdog, true);
    if (servos_[i].dead || limit <= 0 || get(t, xs::kTorqueEnable, false) != 1) continue;
    const double at = last_instruction_ + limit * xs::kBusWatchdogUnit;
    if (now <= at) continue;
    backend_->advance(at);  // the servo stops when its limit passes, not when this is noticed
    put(t, xs::kBusWatchdog, -1);
    update_command(i);
  }
}

bool VirtualBus::bus_watchdog_armed() const {
  for (const Servo& s : servos_)
    if (get(s.table, xs::kBusWatchdog, true) > 0 && get(s.table, xs::kTorqueEnable, false) == 1) return true;
  return false;
}

void VirtualBus::run() {
  std::uint8_t buffer[1024];
  for (;;) {
    pollfd fds[2] = {{master_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    bool armed = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      armed = bus_watchdog_armed();
    }
    const int r = ::poll(fds, 2, armed ? 2 : 100);  // an armed bus watchdog is checked every 2 ms
    if (r < 0 && errno != EINTR) return;
    if (fds[1].revents) return;
    if (armed) {
      std::lock_guard<std::mutex> lock(mutex_);
      trip_bus_watchdogs(clock());
    }
    if (!(fds[0].revents & POLLIN)) continue;
    const ssize_t n = ::read(master_, buffer, sizeof buffer);
    if (n <= 0) continue;
    const double now = clock();
    decoder_.feed(buffer, static_cast<std::size_t>(n));
    while (const DecodeEvent e = decoder_.next()) {
      process(e, now);
      send_pending();
    }
  }
}

}  // namespace symoro::dynamixel
