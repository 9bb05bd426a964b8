// JointState's CDR and its ros2msg definition (symoro/io/ros2_joint_state.hpp).
#include "symoro/io/ros2_joint_state.hpp"

#include <cstring>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace symoro::io::ros2 {

namespace {

// XCDR1 fields from the end of the encapsulation header, in the byte order it names.
class Cdr {
 public:
  Cdr(const std::uint8_t* data, std::size_t size) : p_(data), size_(size) {
    if (size < 4) throw std::invalid_argument(fmt::format("{} bytes: shorter than CDR's 4-byte header", size));
    // Encapsulation kinds: 0x0000 CDR_BE, 0x0001 CDR_LE (PL_CDR and XCDR2 are not what ROS 2 writes
    // for a plain message).
    if (data[0] != 0 || data[1] > 1)
      throw std::invalid_argument(
          fmt::format("encapsulation {:#04x}{:02x} is not plain CDR (0x0000 or 0x0001)", data[0], data[1]));
    little_ = data[1] == 1;
    at_ = 4;
  }

  template <typename T>
  T primitive(const char* field) {
    align(sizeof(T));
    need(sizeof(T), field);
    std::uint8_t b[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = p_[at_ + (little_ ? i : sizeof(T) - 1 - i)];
    at_ += sizeof(T);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }
  std::string string(const char* field) {
    const auto n = primitive<std::uint32_t>(field);
    need(n, field);
    // The length counts the terminating NUL (0 is tolerated: an empty string some writers emit).
    std::string s(reinterpret_cast<const char*>(p_ + at_), n > 0 ? n - 1 : 0);
    if (n > 0 && p_[at_ + n - 1] != 0)
      throw std::invalid_argument(fmt::format("byte {}: {} lacks its terminating NUL", at_ + n - 1, field));
    at_ += n;
    return s;
  }
  std::uint32_t length(const char* field, std::size_t element) {
    const auto n = primitive<std::uint32_t>(field);
    if (n > (size_ - at_) / element)
      throw std::invalid_argument(
          fmt::format("byte {}: {} claims {} elements, {} bytes are left", at_ - 4, field, n, size_ - at_));
    return n;
  }
  std::vector<double> doubles(const char* field) {
    std::vector<double> v(length(field, 8));
    for (double& x : v) x = primitive<double>(field);
    return v;
  }

 private:
  void align(std::size_t n) {
    const std::size_t from_body = at_ - 4;
    const std::size_t pad = (n - from_body % n) % n;
    need(pad, "padding");
    at_ += pad;
  }
  void need(std::size_t n, const char* field) const {
    if (n > size_ - at_)
      throw std::invalid_argument(
          fmt::format("byte {}: {} needs {} bytes, the message has {} left", at_, field, n, size_ - at_));
  }
  const std::uint8_t* p_;
  std::size_t size_, at_ = 0;
  bool little_ = true;
};

// The "type name" lines of a definition's own section (before the first "===" line of its
// dependencies), comments and constants left out.
std::vector<std::pair<std::string, std::string>> own_fields(const std::string& text) {
  std::vector<std::pair<std::string, std::string>> fields;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("===", 0) == 0) break;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string type, name;
    if (!(words >> type >> name)) continue;
    if (name.find('=') != std::string::npos) continue;  // a constant
    fields.emplace_back(type, name);
  }
  return fields;
}

}  // namespace

void check_joint_state_definition(const std::string& text) {
  const std::vector<std::pair<std::string, std::string>> expected = {{"std_msgs/Header", "header"},
                                                                     {"string[]", "name"},
                                                                     {"float64[]", "position"},
                                                                     {"float64[]", "velocity"},
                                                                     {"float64[]", "effort"}};
  auto fields = own_fields(text);
  for (auto& f : fields)
    if (f.first == "Header" || f.first == "std_msgs/msg/Header") f.first = "std_msgs/Header";
  if (fields == expected) return;
  std::string got;
  for (const auto& f : fields) got += (got.empty() ? "" : ", ") + f.first + " " + f.second;
  throw std::invalid_argument("its definition has the fields [" + got +
                              "], not JointState's [std_msgs/Header header, string[] name, float64[] position, "
                              "float64[] velocity, float64[] effort]");
}

JointState decode_joint_state(const std::uint8_t* data, std::size_t size) {
  Cdr cdr(data, size);
  JointState m;
  m.sec = cdr.primitive<std::int32_t>("header.stamp.sec");
  m.nanosec = cdr.primitive<std::uint32_t>("header.stamp.nanosec");
  m.frame_id = cdr.string("header.frame_id");
  m.name.resize(cdr.length("name", 4));
  for (std::string& n : m.name) n = cdr.string("name");
  m.position = cdr.doubles("position");
  m.velocity = cdr.doubles("velocity");
  m.effort = cdr.doubles("effort");
  for (const auto& [field, v] : {std::pair<const char*, const std::vector<double>*>{"position", &m.position},
                                 {"velocity", &m.velocity},
                                 {"effort", &m.effort}})
    if (!v->empty() && v->size() != m.name.size())
      throw std::invalid_argument(fmt::format("{} has {} values for {} names (it must have one per name, or none)",
                                              field, v->size(), m.name.size()));
  return m;
}

}  // namespace symoro::io::ros2
