// Errors in data given to the runtime (logs, trajectory designs, twin configurations), located
// in a file: "file:line: error: message" (line 0 when the problem concerns the whole file), or
// "file:line:column: error: message" when the column says more (a YAML syntax error).
#pragma once

#include <stdexcept>
#include <string>

namespace symoro {

class DataError : public std::runtime_error {
 public:
  DataError(std::string file, int line, const std::string& message)
      : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) +
                           ": error: " + message),
        file_(std::move(file)),
        line_(line) {}
  DataError(std::string file, int line, int column, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message),
        file_(std::move(file)),
        line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

}  // namespace symoro
