#pragma once
// Text matbake writes into files another program parses (Ninja files, shell scripts, Make
// depfiles): one quoting function per language, so that a path or a name is always data, never
// code. What a language cannot hold is refused (an error naming it), never written approximately.
#include <string>
#include <string_view>

#include "matbake/result.hpp"

namespace matbake {

// Why `text` (a path or a name) cannot go into a generated file, or empty when it can: a NUL, a
// newline or a carriage return (a line break ends a shell comment and a Ninja statement alike).
std::string unscriptable(std::string_view text);

// POSIX shell: one word the shell reads back unchanged, single-quoted unless it holds only
// [A-Za-z0-9_./:=%@+,-] (and is not empty), with ' written as '\''.
std::string shell_word(std::string_view word);

// Ninja: a path in a build statement's list ($-escapes for '$', ' ', ':'); an error for what Ninja
// cannot escape ('|', which ends the list, and what unscriptable refuses).
Result<std::string> ninja_path(std::string_view path);

// Ninja: the value of a variable (the text after "name = "): '$' doubled; the caller has refused
// line breaks (unscriptable).
std::string ninja_value(std::string_view value);

// A Make depfile's path in GCC's form, as Ninja (`deps = gcc`, and CMake's DEPFILE under Ninja)
// reads it: ' ', '#' and '$' escaped; an error for a character Ninja's depfile reader takes as a
// separator and has no escape for (quotes, ';', '&', '|', '*', '?', '<', '>', '`', '\', a tab, a
// line break) or a ':' that ends the path.
Result<std::string> depfile_path(std::string_view path);

}  // namespace matbake
