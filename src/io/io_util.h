// Small helpers shared by the mesh and lattice readers/writers: whole-file reading with input errors,
// strict number parsing, shortest/fixed-precision number formatting, and line-aware tokenising.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace sffd::io {

// The whole file as bytes. Throws inputError(path, 0, ...) for a missing, unreadable or empty file, a
// directory, or anything but a regular file (a FIFO, socket or device, before opening it).
std::string readWholeFile(const std::string& path);

// Checks the encoding of a text file read whole: a UTF-16 or UTF-32 byte-order mark, or (unless
// `mayHoldBinary`, for formats with a binary variant) a NUL byte, is an input error naming the file
// (and the line of the NUL); a UTF-8 byte-order mark is removed.
void checkTextEncoding(const std::string& path, std::string& text, bool mayHoldBinary);

// ".obj" for "dir/Mesh.OBJ" (lower case, with the dot; empty when there is none).
std::string lowerExtension(const std::string& path);

// Parses the whole token as a number (a leading '+' is accepted). Underflow gives 0 or a denormal,
// overflow gives +-inf (callers check finiteness). False for anything that is not a number.
bool parseDouble(std::string_view token, double& out);
// Parses the whole token as a decimal integer (leading '+' accepted).
bool parseInt(std::string_view token, long long& out);

// Appends `v` with `digits` significant digits ("%.*g"), or, with digits <= 0, the shortest text
// that reads back to the same double.
void appendNumber(std::string& out, double v, int digits);
std::string formatNumber(double v, int digits = 0);

// 1-based line of a byte offset.
size_t lineOfOffset(std::string_view text, size_t offset);

// An error message made one printable line: control characters (a newline in a JSON key, a file
// name) become '?'. The readers' entry points pass every message through it.
std::string oneLine(std::string_view message);

// A token for an error message: printable, at most 40 characters, quoted.
std::string quoted(std::string_view token);

// Whitespace-separated tokens across lines, each with its 1-based line.
class Tokenizer {
 public:
  explicit Tokenizer(std::string_view text, size_t firstLine = 1) : text_(text), line_(firstLine) {}
  // False at the end of the text.
  bool next(std::string_view& token, size_t& line);
  // The rest of the current line (after the last token read), without the line break; moves to the next line.
  std::string_view restOfLine();
  size_t line() const { return line_; }
  size_t offset() const { return pos_; }
  bool atEnd();   // only whitespace left

 private:
  void skipSpace();
  std::string_view text_;
  size_t pos_ = 0;
  size_t line_;
};

// Lines without their line breaks ("\n", "\r\n" or a lone "\r" at the end of the text).
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line, size_t& lineNo);
  size_t offset() const { return pos_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  size_t line_ = 0;
};

// White space as the C locale has it (space, \t, \n, \r, \f, \v), whatever locale the embedding program set;
// inline because std::isspace, a call per character, was a tenth of reading a large OBJ (perf).
constexpr bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Splits on ASCII white space (isSpace).
void splitTokens(std::string_view line, std::vector<std::string_view>& out);
std::string_view trim(std::string_view s);

// Whether `x` is finite and within float's range: what a file of floats (binary STL, glTF) can hold of a
// double result, which a float would otherwise turn into an infinity.
inline bool withinFloatRange(double x) { return std::abs(x) <= double(std::numeric_limits<float>::max()); }

}  // namespace sffd::io
