// Errors in data given to the runtime (logs, trajectory designs, twin configurations), located
// in a file: "file:line: error: message" (line 0 when the problem concerns the whole file), or
// "file:line:column: error: message" when the column says more (a YAML syntax error).
#pragma once

#include <stdexcept>
#include <string>

namespace symoro {

// A message as long as a reader's input can make it (a 100 MB scalar quoted whole) cut to its
// first 2000 and last 500 characters, saying how many were left out.
inline std::string bounded_message(const std::string& message) {
  constexpr std::size_t kHead = 2000, kTail = 500;
  if (message.size() <= kHead + kTail + 100) return message;
  return message.substr(0, kHead) + " [... " + std::to_string(message.size() - kHead - kTail) +
         " characters left out ...] " + message.substr(message.size() - kTail);
}

class DataError : public std::runtime_error {
 public:
  DataError(std::string file, int line, const std::string& message)
      : std::runtime_error(bounded_message(file) + (line > 0 ? ":" + std::to_string(line) : std::string()) +
                           ": error: " + bounded_message(message)),
        file_(std::move(file)),
        line_(line) {}
  DataError(std::string file, int line, int column, const std::string& message)
      : std::runtime_error(bounded_message(file) + ":" + std::to_string(line) + ":" + std::to_string(column) +
                           ": error: " + bounded_message(message)),
        file_(std::move(file)),
        line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

}  // namespace symoro
