#include "io/io_util.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <sffd/error.h>

namespace sffd::io {
namespace fs = std::filesystem;

std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) throw inputError(path, 0, "cannot read: is a directory");
  // A FIFO would block the open until something writes to it, and /dev/zero never ends.
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw inputError(path, 0, "cannot read: not a regular file (a FIFO, socket or device)");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    int e = errno;
    throw inputError(path, 0, std::string("cannot read: ") + (e ? std::strerror(e) : "cannot open file"));
  }
  in.seekg(0, std::ios::end);
  std::streamoff size = in.tellg();
  if (size < 0) throw inputError(path, 0, "cannot read: cannot determine the file size");
  if (size == 0) throw inputError(path, 0, "empty file");
  in.seekg(0, std::ios::beg);
  std::string data(size_t(size), '\0');
  in.read(data.data(), size);
  if (in.gcount() != size) throw inputError(path, 0, "cannot read: read failed");
  return data;
}

void checkTextEncoding(const std::string& path, std::string& text, bool mayHoldBinary) {
  auto startsWith = [&](std::string_view p) { return text.size() >= p.size() && std::string_view(text).substr(0, p.size()) == p; };
  using namespace std::string_view_literals;
  if (startsWith("\xFF\xFE\0\0"sv) || startsWith("\0\0\xFE\xFF"sv))
    throw inputError(path, 0, "UTF-32 text (byte-order mark) is not supported; save the file as UTF-8 or ASCII");
  if (startsWith("\xFF\xFE"sv) || startsWith("\xFE\xFF"sv))
    throw inputError(path, 0, "UTF-16 text (byte-order mark " + std::string(text[0] == '\xFF' ? "FF FE" : "FE FF") +
                                  ") is not supported; save the file as UTF-8 or ASCII");
  if (startsWith("\xEF\xBB\xBF"sv)) {
    text = text.substr(3);
    if (text.empty()) throw inputError(path, 0, "empty file (only a UTF-8 byte-order mark)");
  }
  if (mayHoldBinary) return;
  size_t nul = text.find('\0');
  if (nul == std::string::npos) return;
  // UTF-16 without a byte-order mark: every other byte of ASCII text is NUL.
  bool utf16 = text.size() >= 4 && ((text[0] != '\0' && text[1] == '\0' && text[3] == '\0') ||
                                    (text[0] == '\0' && text[1] != '\0' && text[2] == '\0'));
  if (utf16) throw inputError(path, 0, "UTF-16 text is not supported; save the file as UTF-8 or ASCII");
  throw inputError(path, lineOfOffset(text, nul), "binary data (a NUL byte) in a text file");
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool parseDouble(std::string_view t, double& out) {
  if (!t.empty() && t[0] == '+') {
    t.remove_prefix(1);
    if (!t.empty() && (t[0] == '-' || t[0] == '+')) return false;
  }
  if (t.empty()) return false;
  auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
  if (end != t.data() + t.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves `out` untouched on range errors: strtod gives +-HUGE_VAL or the underflowed value.
    std::string copy(t);
    out = std::strtod(copy.c_str(), nullptr);
    return true;
  }
  return ec == std::errc();
}

bool parseInt(std::string_view t, long long& out) {
  if (!t.empty() && t[0] == '+') {
    t.remove_prefix(1);
    if (!t.empty() && (t[0] == '-' || t[0] == '+')) return false;
  }
  if (t.empty()) return false;
  auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
  return ec == std::errc() && end == t.data() + t.size();
}

void appendNumber(std::string& out, double v, int digits) {
  char buf[64];
  std::to_chars_result r = digits > 0 ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits)
                                      : std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

std::string formatNumber(double v, int digits) {
  std::string s;
  appendNumber(s, v, digits);
  return s;
}

size_t lineOfOffset(std::string_view text, size_t offset) {
  offset = std::min(offset, text.size());
  return 1 + size_t(std::count(text.begin(), text.begin() + ptrdiff_t(offset), '\n'));
}

std::string oneLine(std::string_view message) {
  std::string s(message);
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return s;
}

std::string quoted(std::string_view t) {
  std::string s = "'";
  size_t n = std::min<size_t>(t.size(), 40);
  for (size_t i = 0; i < n; ++i) {
    unsigned char c = static_cast<unsigned char>(t[i]);
    s += (c >= 32 && c < 127) ? char(c) : '?';
  }
  if (t.size() > n) s += "...";
  return s + "'";
}

void Tokenizer::skipSpace() {
  while (pos_ < text_.size()) {
    char c = text_[pos_];
    if (c == '\n') ++line_;
    else if (!isSpace(c)) break;
    ++pos_;
  }
}

bool Tokenizer::next(std::string_view& token, size_t& line) {
  skipSpace();
  if (pos_ >= text_.size()) return false;
  size_t start = pos_;
  while (pos_ < text_.size() && !isSpace(text_[pos_])) ++pos_;
  token = text_.substr(start, pos_ - start);
  line = line_;
  return true;
}

std::string_view Tokenizer::restOfLine() {
  size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  std::string_view rest = text_.substr(start, pos_ - start);
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
  return rest;
}

bool Tokenizer::atEnd() {
  skipSpace();
  return pos_ >= text_.size();
}

bool LineReader::next(std::string_view& line, size_t& lineNo) {
  if (pos_ >= text_.size()) return false;
  size_t end = text_.find('\n', pos_);
  size_t next = end == std::string_view::npos ? text_.size() : end + 1;
  if (end == std::string_view::npos) end = text_.size();
  line = text_.substr(pos_, end - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = next;
  lineNo = ++line_;
  return true;
}

void splitTokens(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSpace(line[i])) ++i;
    size_t s = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    if (i > s) out.push_back(line.substr(s, i - s));
  }
}

std::string_view trim(std::string_view s) {
  size_t b = 0, e = s.size();
  while (b < e && isSpace(s[b])) ++b;
  while (e > b && isSpace(s[e - 1])) --e;
  return s.substr(b, e - b);
}

}  // namespace sffd::io
