// Parsing replay-script lines and key names into Commands (view_script.h). Each verb has an argument
// pattern: i integer, n finite number, f file name, or a fixed list of words.
#include "apps/view/view_script.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <sffd/error.h>

namespace sffd::view {
namespace {

struct Verb {
  const char* name;
  const char* pattern;                     // per argument: i, n, f, w (a word from `words`)
  std::vector<std::string> words;          // allowed words for 'w'
  const char* usage;
};

const std::vector<std::string> kFlags = {"wireframe", "edges", "normals", "heatmap", "lattice", "hud"};

const std::vector<Verb>& verbs() {
  static const std::vector<Verb> v = {
      {"drag", "iiinnn", {}, "drag I J K DX DY DZ (control point (I,J,K) moved by a model-space vector)"},
      {"drag-screen", "nnnn", {}, "drag-screen X Y DX DY (the point under pixel X,Y moved DX,DY pixels)"},
      {"move", "nnn", {}, "move DX DY DZ (the selected points moved by a model-space vector)"},
      {"select", "*", {}, "select all|none|I J K [I J K ...]"},
      {"select-box", "nnnn", {}, "select-box X0 Y0 X1 Y1 (the points inside the pixel rectangle)"},
      {"undo", "", {}, "undo"},
      {"redo", "", {}, "redo"},
      {"reset", "", {}, "reset (every point back where it was loaded; undoable)"},
      {"method", "w", {"smooth", "accurate", "classic"}, "method smooth|accurate|classic"},
      {"clip", "w", {"regular", "knot-box"}, "clip regular|knot-box"},
      {"toggle", "w", kFlags, "toggle wireframe|edges|normals|heatmap|lattice|hud"},
      {"set", "ww", {}, "set FLAG on|off"},
      {"view", "nn", {}, "view AZIMUTH ELEVATION (degrees, as render --view)"},
      {"orbit", "nn", {}, "orbit DAZ DEL (degrees)"},
      {"pan", "nn", {}, "pan DX DY (pixels)"},
      {"zoom", "n", {}, "zoom FACTOR (> 1 comes closer)"},
      {"fit", "", {}, "fit (frame the result as render does)"},
      {"resize", "ii", {}, "resize W H (pixels; 0 0 acts as a minimised window)"},
      {"screenshot", "f", {}, "screenshot FILE.png"},
      {"save-lattice", "f", {}, "save-lattice FILE (.json .npy .prm .vtk)"},
      {"load-lattice", "f", {}, "load-lattice FILE"},
      {"save-mesh", "f", {}, "save-mesh FILE (.obj .ply .off .stl)"},
      {"frame", "", {}, "frame (draw one more frame)"},
      {"press", "", {}, "press (a mouse button goes down: until release, moves are drawn as drafts)"},
      {"release", "", {}, "release (the button goes up: the full-quality result is drawn)"},
      {"key", "f", {}, "key NAME (a key press: w, ctrl+z, f1 ...)"},
      {"quit", "", {}, "quit"},
  };
  return v;
}

bool number(const std::string& s, double& out) {
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size() && std::isfinite(out);
}

Error bad(const std::string& what) { return Error(ErrorKind::Input, what); }

}  // namespace

const std::vector<std::string>& flagNames() { return kFlags; }

std::optional<Command> parseCommand(const std::string& text) {
  std::string line = text.substr(0, text.find('#'));
  std::istringstream in(line);
  std::vector<std::string> tokens;
  for (std::string t; in >> t;) tokens.push_back(t);
  if (tokens.empty()) return std::nullopt;
  const Verb* verb = nullptr;
  for (const Verb& v : verbs())
    if (tokens[0] == v.name) verb = &v;
  if (!verb) throw bad("unknown command '" + tokens[0] + "'");
  Command c;
  c.verb = verb->name;
  c.words.assign(tokens.begin() + 1, tokens.end());
  const std::string pattern = verb->pattern;
  auto usage = [&] { return bad(std::string("usage: ") + verb->usage); };
  if (pattern == "*") {   // select
    if (c.words.size() == 1 && (c.words[0] == "all" || c.words[0] == "none")) return c;
    if (c.words.empty() || c.words.size() % 3 != 0) throw usage();
    for (const std::string& w : c.words) {
      double v = 0;
      if (!number(w, v) || v != std::floor(v) || v < 0) throw bad("select: '" + w + "' is not a point index");
      c.numbers.push_back(v);
    }
    return c;
  }
  if (c.words.size() != pattern.size()) throw usage();
  for (size_t i = 0; i < pattern.size(); ++i) {
    const std::string& w = c.words[i];
    double v = 0;
    switch (pattern[i]) {
      case 'i':
        if (!number(w, v) || v != std::floor(v) || std::abs(v) > 1e9) throw bad(c.verb + ": '" + w + "' is not an integer");
        c.numbers.push_back(v);
        break;
      case 'n':
        if (!number(w, v)) throw bad(c.verb + ": '" + w + "' is not a finite number");
        c.numbers.push_back(v);
        break;
      case 'w': {
        const std::vector<std::string>& allowed = c.verb == "set" ? (i == 0 ? kFlags : std::vector<std::string>{"on", "off"})
                                                                   : verb->words;
        bool ok = false;
        for (const std::string& a : allowed) ok |= a == w;
        if (!ok) throw usage();
        break;
      }
      default: break;   // 'f': any word
    }
  }
  if (c.verb == "zoom" && !(c.numbers[0] > 0)) throw bad("zoom: the factor must be positive");
  if (c.verb == "resize" && (c.numbers[0] < 0 || c.numbers[1] < 0 || c.numbers[0] > 8192 || c.numbers[1] > 8192))
    throw bad("resize: the size must be 0..8192 pixels");
  if (c.verb == "key" && !keyCommand(c.words[0])) throw bad("key: '" + c.words[0] + "' is not a bound key");
  return c;
}

std::vector<Command> readScript(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw inputError(path, 0, "cannot open the script");
  std::vector<Command> out;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    try {
      if (auto c = parseCommand(line)) {
        c->line = n;
        out.push_back(std::move(*c));
      }
    } catch (const Error& e) {
      throw inputError(path, n, e.what());
    }
  }
  return out;
}

namespace {
struct Binding {
  const char* key;
  const char* command;   // a script line
  const char* help;
};
const Binding kBindings[] = {
    {"ctrl+z", "undo", "undo the last move"},
    {"ctrl+y", "redo", "redo"},
    {"shift+ctrl+z", "redo", "redo"},
    {"m", "method next", "next method: smooth, accurate, classic"},
    {"c", "clip next", "next clipping: regular, knot-box"},
    {"w", "toggle wireframe", "wireframe (tessellation triangles)"},
    {"e", "toggle edges", "sub-triangle (patch) edges"},
    {"n", "toggle normals", "normals of the tessellation vertices"},
    {"h", "toggle heatmap", "error heat map against the exact FFD"},
    {"l", "toggle lattice", "lattice points and edges"},
    {"f1", "toggle hud", "frame time and stage times on screen"},
    {"f", "fit", "frame the result as sffd render does"},
    {"a", "select all", "select every control point"},
    {"escape", "select none", "clear the selection"},
    {"r", "reset", "every point back where it was loaded (undoable)"},
    {"s", "screenshot auto", "screenshot to OUT-DIR/sffd-view-N.png"},
    {"ctrl+s", "save-lattice auto", "save the lattice to OUT-DIR/sffd-view-lattice.json"},
    {"o", "save-mesh auto", "save the result to OUT-DIR/sffd-view-mesh.obj"},
    {"q", "quit", "quit"},
};
}  // namespace

std::optional<Command> keyCommand(const std::string& key) {
  for (const Binding& b : kBindings) {
    if (key != b.key) continue;
    std::istringstream in(b.command);
    Command c;
    in >> c.verb;
    for (std::string w; in >> w;) c.words.push_back(w);
    return c;   // "next" and "auto" arguments are resolved by the executor
  }
  return std::nullopt;
}

std::vector<std::pair<std::string, std::string>> keyBindings() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Binding& b : kBindings) out.push_back({b.key, b.help});
  return out;
}

}  // namespace sffd::view
