#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <cmath>
#include <sstream>

#include "apps/sffd/cli.h"

#include <utility>
#include <sffd/error.h>

namespace sffd::cli {
namespace {

Error usage(const std::string& what) { return Error(ErrorKind::Input, what); }

// Canonical long name and aliases of an option spec ("--output|-o").
std::vector<std::string> namesOf(const OptionSpec& o) {
  std::vector<std::string> names;
  std::stringstream ss(o.name);
  std::string n;
  while (std::getline(ss, n, '|')) names.push_back(n);
  return names;
}

const OptionSpec* findOption(const CommandSpec& spec, const std::string& arg, std::string& canonical) {
  for (const OptionSpec& o : spec.options) {
    auto names = namesOf(o);
    for (const std::string& n : names)
      if (n == arg) {
        canonical = names.front();
        return &o;
      }
  }
  return nullptr;
}

}  // namespace

namespace {

// What the user probably meant by an extra positional argument: a lattice or output given without its option.
std::string positionalHint(const CommandSpec& spec, const std::string& arg, const std::string& after) {
  std::string canonical;
  auto has = [&](const char* name) { return findOption(spec, name, canonical) != nullptr; };
  if (!after.empty()) return " (" + after + " takes one value)";
  std::string ext = arg.size() > 4 ? arg.substr(arg.size() - 5) : arg;
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  auto endsWith = [&](const char* e) { return ext.size() >= std::strlen(e) && ext.compare(ext.size() - std::strlen(e), std::string::npos, e) == 0; };
  if (has("--lattice") && (endsWith(".json") || endsWith(".prm") || endsWith(".npy"))) return " (the lattice is given with -l)";
  if (has("--output")) return " (the output is given with -o)";
  return "";
}

}  // namespace

ParsedArgs parseArgs(const CommandSpec& spec, int argc, char** argv) {
  ParsedArgs a;
  a.command = &spec;
  std::string lastValued;   // the option whose value the previous argument was, for hints
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.size() > 1 && arg[0] == '-' && !(arg.size() > 1 && (std::isdigit(arg[1]) || arg[1] == '.'))) {
      std::string value;
      size_t eq = arg.find('=');
      bool inlineValue = arg.rfind("--", 0) == 0 && eq != std::string::npos;
      if (inlineValue) {
        value = arg.substr(eq + 1);
        arg = arg.substr(0, eq);
      }
      std::string canonical, other;
      const OptionSpec* o = findOption(spec, arg, canonical);
      if (!o) throw usage("unknown option '" + arg + "' for 'sffd " + spec.name + "' (see sffd " + spec.name + " --help)");
      lastValued.clear();
      if (o->value) {
        if (!inlineValue) {
          if (i + 1 >= argc) throw usage("option " + canonical + " needs a value (" + o->value + ")");
          // "-l -o x": the next argument is an option of this command, not a value.
          if (argv[i + 1][0] == '-' && findOption(spec, argv[i + 1], other))
            throw usage("option " + canonical + " needs a value (" + o->value + "), not the option '" + argv[i + 1] + "'");
          value = argv[++i];
        }
        if (o->repeatable) {
          a.repeated[canonical].push_back(value);
          a.values.try_emplace(canonical, value);
          lastValued = canonical;
          continue;
        }
        // One value per option: "-l a -l b" would silently keep b.
        if (auto it = a.values.find(canonical); it != a.values.end())
          throw usage("option " + canonical + " is given twice ('" + it->second + "' and '" + value + "'); give it once");
        a.values[canonical] = value;
        lastValued = canonical;
      } else {
        if (inlineValue) throw usage("option " + canonical + " takes no value");
        a.values[canonical] = "1";
      }
    } else {
      if (a.positional.size() >= spec.maxPositional && !a.has("--help"))
        throw usage("unexpected argument '" + arg + "'" + positionalHint(spec, arg, lastValued) + " (usage: sffd " + spec.name +
                    " " + spec.usage + ")");
      a.positional.push_back(arg);
      lastValued.clear();
    }
  }
  if (a.has("--help")) return a;
  if (a.positional.size() < spec.minPositional)
  {
    // The first placeholder of the usage line ("MESH") names what is missing.
    std::string first = std::string(spec.usage).substr(0, std::string(spec.usage).find(' '));
    bool placeholder = !first.empty() && std::all_of(first.begin(), first.end(), [](char c) { return std::isupper(static_cast<unsigned char>(c)) || c == '_'; });
    throw usage("missing " + (placeholder && a.positional.empty() ? first : std::string("an argument")) + " (usage: sffd " + spec.name +
                " " + spec.usage + ")");
  }
  return a;
}

std::vector<std::string> ParsedArgs::all(const std::string& name) const {
  if (auto it = repeated.find(name); it != repeated.end()) return it->second;
  if (auto it = values.find(name); it != values.end()) return {it->second};
  return {};
}

std::string ParsedArgs::get(const std::string& name, const std::string& fallback) const {
  auto it = values.find(name);
  return it == values.end() ? fallback : it->second;
}

std::string ParsedArgs::requireValue(const std::string& name) const {
  auto it = values.find(name);
  if (it == values.end()) throw usage("option " + name + " is required (usage: sffd " + command->name + " " + command->usage + ")");
  return it->second;
}

double ParsedArgs::getDouble(const std::string& name, double fallback) const {
  auto it = values.find(name);
  if (it == values.end()) return fallback;
  const std::string& s = it->second;
  double v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(v))
    throw usage("option " + name + " needs a finite number, not '" + s + "'");
  return v;
}

int ParsedArgs::getInt(const std::string& name, int fallback) const {
  auto it = values.find(name);
  if (it == values.end()) return fallback;
  const std::string& s = it->second;
  int v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size()) throw usage("option " + name + " needs an integer, not '" + s + "'");
  return v;
}

int ParsedArgs::getInt(const std::string& name, int fallback, int lo, int hi) const {
  auto it = values.find(name);
  if (it == values.end()) return fallback;
  const std::string& s = it->second;
  int v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  // A word, a number past int's range and one outside lo..hi get the one message that names the range.
  if (ec != std::errc() || p != s.data() + s.size() || v < lo || v > hi)
    throw usage("option " + name + " needs an integer " + std::to_string(lo) + ".." + std::to_string(hi) + ", not '" + s + "'");
  return v;
}

std::vector<std::string> ParsedArgs::getList(const std::string& name, const std::string& fallback) const {
  const std::string text = get(name, fallback);
  std::vector<std::string> out;
  if (text.empty()) return out;
  for (size_t start = 0;;) {
    const size_t comma = text.find(',', start);
    out.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (out.back().empty()) throw usage("option " + name + " needs names separated by single commas, not '" + text + "'");
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

std::array<int, 3> ParsedArgs::getTriple(const std::string& name, std::array<int, 3> fallback, int lo, int hi) const {
  auto it = values.find(name);
  if (it == values.end()) return fallback;
  std::array<int, 3> r{};
  const std::string& s = it->second;
  int n = 0;
  bool outside = false;   // a number, but past lo..hi (or int's range)
  // Every part between commas must be an integer, an empty last one too ("5,5,5," and "5," are refused).
  for (size_t start = 0;;) {
    const size_t comma = s.find(',', start), end = comma == std::string::npos ? s.size() : comma;
    int v = 0;
    auto [p, ec] = std::from_chars(s.data() + start, s.data() + end, v);
    if (n >= 3 || p != s.data() + end || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
      n = 4;
      break;
    }
    outside |= ec != std::errc() || v < lo || v > hi;
    r[n++] = v;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  // The one rule of list options (docs/CLI.md): one value for every axis, or exactly three.
  if (n == 1) r = {r[0], r[0], r[0]};
  else if (n != 3)
    throw usage("option " + name + " needs one integer for all axes or three (U,V,W) like 5 or 5,6,7, not '" + it->second + "'");
  if (outside)
    throw usage("option " + name + " needs one integer " + std::to_string(lo) + ".." + std::to_string(hi) +
                " for all axes or three, not '" + it->second + "'");
  return r;
}

std::string helpText(const CommandSpec& spec) {
  std::ostringstream o;
  o << "usage: sffd " << spec.name << " " << spec.usage << "\n" << spec.summary << "\n\noptions:\n";
  for (const OptionSpec& opt : spec.options) {
    std::string left = std::string("  ") + opt.name + (opt.value ? std::string(" ") + opt.value : "");
    o << left << std::string(left.size() < 30 ? 30 - left.size() : 1, ' ') << opt.help << "\n";
  }
  return o.str();
}

void note(const ParsedArgs& args, const std::string& line) {
  if (!args.has("--quiet")) fprintf(stderr, "sffd: %s\n", line.c_str());
}

namespace {
std::vector<std::string>& warnings() {
  static std::vector<std::string> w;
  return w;
}
}  // namespace

void warnOnSuccess(const std::string& line) { warnings().push_back(line); }

std::vector<std::string> takeWarnings() { return std::exchange(warnings(), {}); }

Mesh readMeshWarning(const std::string& path, const MeshReadOptions& options) {
  Mesh mesh = readMesh(path, options);
  for (const std::string& w : mesh.warnings) warnOnSuccess(w);
  return mesh;
}

}  // namespace sffd::cli
