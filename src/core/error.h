// sffd::Error: the one exception type that reaches the command line. Its kind decides the exit status
// documented in docs/CLI.md (2 bad input or usage, 3 missing or unusable device, 1 anything else).
#pragma once
#include <stdexcept>
#include <string>

namespace sffd {

enum class ErrorKind { Input = 2, Device = 3, Internal = 1 };

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  ErrorKind kind() const { return kind_; }
  int exitStatus() const { return static_cast<int>(kind_); }

 private:
  ErrorKind kind_;
};

// "file:line: what" (line 0: "file: what"), the form every bad-input message takes.
inline Error inputError(const std::string& file, size_t line, const std::string& what) {
  std::string where = file;
  if (line > 0) where += ":" + std::to_string(line);
  return Error(ErrorKind::Input, where.empty() ? what : where + ": " + what);
}
inline Error deviceError(const std::string& what) { return Error(ErrorKind::Device, what); }

}  // namespace sffd
