#pragma once
// Errors that user input can cause are values, not exceptions or prints: the library returns them
// and only the CLI prints `matbake: error: <path>: <problem>` and picks the exit code.
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace matbake {

// `text` with its control characters written as escapes (\n, \r, \t, \xNN): a name from a file
// that holds a newline cannot split a message into two lines.
inline std::string escape_control(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const auto u = static_cast<unsigned char>(c);
    const auto next = [&](std::size_t k) { return i + k < text.size() ? static_cast<unsigned char>(text[i + k]) : 0u; };
    // UTF-8 controls a terminal acts on: C1 (U+0080–U+009F, NEL among them) and the bidirectional
    // embeddings, overrides and isolates (U+202A–U+202E, U+2066–U+2069), written as \uXXXX.
    const bool c1 = u == 0xc2 && next(1) >= 0x80 && next(1) <= 0x9f;
    const bool bidi = u == 0xe2 && ((next(1) == 0x80 && next(2) >= 0xaa && next(2) <= 0xae) ||
                                    (next(1) == 0x81 && next(2) >= 0xa6 && next(2) <= 0xa9));
    if (c1 || bidi) {
      const unsigned code = c1 ? next(1) : (next(1) == 0x80 ? 0x2000u : 0x2040u) + (next(2) & 0x3fu);
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\u%04x", code);
      out += hex;
      i += c1 ? 1 : 2;
      continue;
    }
    if (u >= 0x20 && u != 0x7f) {
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    }
  }
  return out;
}

// A setting named in a library message: the library says which parameter (and value), the door that
// shows the message spells it — "--texture-rounding multiple-of-4" on the command line,
// `texture_rounding = "multiple-of-4"` in a manifest's words — so no flag is written in lib/.
// Held in the text between control characters that the door replaces before escaping the rest.
inline std::string mention(std::string_view name, std::string_view value = {}) {
  std::string out = "\x02";
  out.append(name);
  if (!value.empty()) out.append("\x1f").append(value);
  return out.append("\x03");
}

// How a door spells a mention: its parameter's name and value ("" when none).
using MentionSpelling = std::string (*)(const std::string& name, const std::string& value);

// The manifest's spelling, the default: `name = value`, the value quoted unless a number or true/false.
inline std::string key_mention(const std::string& name, const std::string& value) {
  if (value.empty()) return name;
  const bool bare = value == "true" || value == "false" || value.find_first_not_of("0123456789.-") == std::string::npos;
  return name + " = " + (bare ? value : "\"" + value + "\"");
}

// `text` with each mention spelt.
inline std::string spell_mentions(std::string_view text, MentionSpelling spell) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t start = text.find('\x02', at), end = start == std::string_view::npos ? start : text.find('\x03', start);
    if (end == std::string_view::npos) return out.append(text.substr(at));
    const std::string_view inner = text.substr(start + 1, end - start - 1);
    const std::size_t split = std::min(inner.find('\x1f'), inner.size());
    out.append(text.substr(at, start - at))
        .append(spell(std::string(inner.substr(0, split)), std::string(inner.substr(std::min(split + 1, inner.size())))));
    at = end + 1;
  }
  return out;
}

struct Error {
  std::string path;     // the file the problem is about; empty when it is about no file
  std::string message;  // one line, lower case, no trailing period; settings in it as mention()s
  bool usage = false;   // the command was called wrongly (exit 2), rather than given bad input (exit 1)

  // One line whatever the path and message hold, its mentions spelt as the door says.
  std::string to_string(MentionSpelling spell = key_mention) const {
    const std::string text = spell_mentions(message, spell);
    return escape_control(path.empty() ? text : path + ": " + text);
  }
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::move(value)) {}
  Result(Error error) : state_(std::move(error)) {}

  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() { return std::get<0>(state_); }
  const T& value() const { return std::get<0>(state_); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Error& error() const { return std::get<1>(state_); }

 private:
  std::variant<T, Error> state_;
};

// For operations that produce nothing but can fail.
using Status = Result<std::monostate>;
inline Status success() { return std::monostate{}; }

// A module's edge: `body` (returning a Result or Status) run so that an exception from a dependency
// (nlohmann, tinygltf, toml++, OIIO, std::bad_alloc, std::length_error, filesystem, ...) comes back
// as one Error about `path` rather than ending the process.
template <class Body>
auto guarded(const std::string& path, Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return Error{path, "out of memory"};
  } catch (const std::exception& e) {
    std::string what = e.what();
    what = what.substr(0, what.find('\n'));
    return Error{path, what.empty() ? "failed (an exception without a message)" : what};
  }
}

}  // namespace matbake
