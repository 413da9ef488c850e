#pragma once
// Small, strict helpers for the text formats kestrel reads (TUM lists and trajectories,
// world files, g2o): whitespace-separated fields, numbers that must be whole tokens; and the
// escaping of outside text before it is shown.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace kestrel {

/// Fields of `line` split on spaces and tabs (a trailing '\r' is ignored).
std::vector<std::string_view> split_fields(std::string_view line);

/// True for a blank line or one whose first non-blank character is '#'.
bool is_comment_or_blank(std::string_view line);

/// The whole token as a double ("nan" and "inf" parse; check finiteness yourself), or empty.
std::optional<double> parse_double(std::string_view token);
/// The whole token as a base-10 integer, or empty.
std::optional<long long> parse_int(std::string_view token);

/// `v` as printf's %g (six significant digits): the one way a number is written into an error
/// message ("must be in [0.01, 1] m per pixel, got 1e+06").
std::string number_text(double v);

/// `text` with every byte that does not print escaped: \n, \t, \r, other control bytes and
/// bytes that are not valid UTF-8 as \xHH; each character of `also` gets a backslash before it.
/// The one escaping for text that reaches a terminal or a file from outside input (error
/// messages, heartbeat reasons, INI values): a damaged file's bytes may be terminal codes.
std::string escape_bytes(std::string_view text, std::string_view also = {});

}  // namespace kestrel
