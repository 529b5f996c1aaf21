// The command layer of `sffd view`: every user action (a key, a mouse gesture, a line of a replay
// script) becomes one Command, so the replay tests exercise the same code as the keys. This file is
// the parser (script lines and key names to Commands); view_app.cpp executes them.
//
// Script format: one command per line, words separated by blanks, `#` starts a comment, blank lines
// are skipped. See docs/CLI.md ("sffd view") for the list.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace sffd::view {

struct Command {
  std::string verb;                 // canonical name, e.g. "drag"
  std::vector<std::string> words;   // the arguments as written
  std::vector<double> numbers;      // the numeric arguments, in order
  size_t line = 0;                  // script line (0: from a key or the mouse)
};

// Parses one line; nullopt for a blank or comment line. Throws an input Error (no file:line prefix)
// naming what is wrong.
std::optional<Command> parseCommand(const std::string& line);

// Reads a whole script; errors are "SCRIPT:LINE: what" input Errors.
std::vector<Command> readScript(const std::string& path);

// The command a key press gives ("w", "ctrl+z", "shift+ctrl+z", "f1", "escape"...); nullopt for an
// unbound key. Names are lower case; modifiers first, in the order shift, ctrl, alt.
std::optional<Command> keyCommand(const std::string& key);

// Every key binding as (key, what it does), for --help and the README.
std::vector<std::pair<std::string, std::string>> keyBindings();

// The flags `toggle` and `set` accept.
const std::vector<std::string>& flagNames();

}  // namespace sffd::view
