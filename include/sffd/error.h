// sffd/error.h: sffd::Error, the one exception type the library throws. Its kind says whose the
// problem is; the command-line tool turns it into its exit status (docs/CLI.md: 2 bad input or usage,
// 3 missing or unusable device, 1 anything else, cancelled included). what() is one line,
// "file:line: what" when a line of an input file is at fault.
#pragma once
#include <stdexcept>
#include <string>

namespace sffd {

enum class ErrorKind {
  Input = 2,      // bad input data or options
  Device = 3,     // no usable device, or the device refused the work (out of memory, lost)
  Internal = 1,   // anything else
  Cancelled = 4,  // a progress callback returned false (the tool exits 1)
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  ErrorKind kind() const { return kind_; }
  int exitStatus() const { return kind_ == ErrorKind::Cancelled ? 1 : static_cast<int>(kind_); }

 private:
  ErrorKind kind_;
};

// "file:line: what" (line 0: "file: what"), the form every bad-input message takes.
inline Error inputError(const std::string& file, size_t line, const std::string& what) {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on ":" + std::to_string(line).
  std::string where = file;
  if (line > 0) where.append(":").append(std::to_string(line));
  return Error(ErrorKind::Input, where.empty() ? what : where.append(": ").append(what));
}
inline Error deviceError(const std::string& what) { return Error(ErrorKind::Device, what); }

}  // namespace sffd
