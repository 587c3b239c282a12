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
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
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

struct Error {
  std::string path;     // the file the problem is about; empty when it is about no file
  std::string message;  // one line, lower case, no trailing period
  bool usage = false;   // the command was called wrongly (exit 2), rather than given bad input (exit 1)

  // One line whatever the path and message hold.
  std::string to_string() const { return escape_control(path.empty() ? message : path + ": " + message); }
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
