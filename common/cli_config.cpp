#include "common/cli_config.h"

#include <cctype>
#include <cstdio>
#include <istream>
#include <sstream>

#include "common/text.h"

namespace kestrel::cli {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The option a key names, looked up as CLI11 does for a configuration item.
const CLI::Option* option_for(const CLI::App& app, const std::string& key) {
  if (const CLI::Option* o = app.get_option_no_throw("--" + key)) return o;
  if (key.size() == 1)
    if (const CLI::Option* o = app.get_option_no_throw("-" + key)) return o;
  return app.get_option_no_throw(key);
}

// The values after a key's '='; a list may take further lines from `input`, counted in `line`.
class ValueParser {
 public:
  ValueParser(std::string_view text, std::istream& input, int& line)
      : text_(text), input_(input), line_(line), first_line_(line) {}

  std::vector<std::string> parse() {
    skip_blanks();
    if (at_end() || peek() == '#') return {""};  // `key =`: the empty string
    std::vector<std::string> values;
    if (peek() == '[') {
      ++pos_;
      parse_list(values);
      skip_blanks();
      if (!at_end() && peek() != '#') fail("text after the list's ']'");
      return values;
    }
    while (true) {
      values.push_back(element(false));
      skip_blanks();
      if (at_end() || peek() == '#') return values;
      if (peek() == ',') {
        ++pos_;
        skip_blanks();
        if (at_end() || peek() == '#') fail("nothing after the last ','");
        if (peek() == ',') fail("an empty element between two ','");
      }
    }
  }

 private:
  void parse_list(std::vector<std::string>& values) {
    bool want_value = true;
    while (true) {
      skip_blanks();
      if (at_end() || peek() == '#') {  // the list goes on on the next line
        std::string next;
        if (!std::getline(input_, next)) throw ConfigLineError(first_line_, "a list without its closing ']'");
        ++line_;
        held_ = next;
        text_ = held_;
        pos_ = 0;
        continue;
      }
      if (peek() == ']') {
        if (values.empty()) fail("an empty list");
        if (want_value) fail("a ',' before the list's ']'");
        ++pos_;
        return;
      }
      if (peek() == ',') {
        if (want_value) fail("an empty element in a list");
        ++pos_;
        want_value = true;
        continue;
      }
      if (!want_value) fail("expected ',' or ']' between the list's elements");
      values.push_back(element(true));
      want_value = false;
    }
  }

  std::string element(bool in_list) {
    const char c = peek();
    if (c == '"') return double_quoted();
    if (c == '\'') {
      const size_t end = text_.find('\'', pos_ + 1);
      if (end == std::string_view::npos) fail("a string without its closing quote");
      std::string s(text_.substr(pos_ + 1, end - pos_ - 1));
      pos_ = end + 1;
      after_quote();
      return s;
    }
    const size_t start = pos_;
    while (!at_end() && !is_blank(peek()) && peek() != ',' && !(in_list && peek() == ']')) ++pos_;
    return std::string(text_.substr(start, pos_ - start));
  }

  std::string double_quoted() {
    std::string s;
    for (++pos_; !at_end(); ++pos_) {
      const char c = peek();
      if (c == '"') {
        ++pos_;
        after_quote();
        return s;
      }
      if (c != '\\' || pos_ + 1 >= text_.size()) {
        s += c;
        continue;
      }
      const char e = text_[++pos_];
      if (e == 'n') s += '\n';
      else if (e == 't') s += '\t';
      else if (e == 'r') s += '\r';
      else if (e == '"' || e == '\\') s += e;
      else if (e == 'x' && pos_ + 2 < text_.size() && std::isxdigit(static_cast<unsigned char>(text_[pos_ + 1])) &&
               std::isxdigit(static_cast<unsigned char>(text_[pos_ + 2]))) {
        s += static_cast<char>(std::stoi(std::string(text_.substr(pos_ + 1, 2)), nullptr, 16));
        pos_ += 2;
      } else {
        s += '\\';  // not an escape: "C:\dir" and "\d+" mean what they say
        s += e;
      }
    }
    fail("a string without its closing quote");
  }

  void after_quote() {
    if (!at_end() && !is_blank(peek()) && peek() != ',' && peek() != ']')
      fail("text right after a closing quote");
  }

  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return text_[pos_]; }
  void skip_blanks() {
    while (!at_end() && (is_blank(peek()) || peek() == '\r')) ++pos_;
  }
  [[noreturn]] void fail(const std::string& what) const { throw ConfigLineError(line_, what); }

  std::string_view text_;
  std::string held_;  // the continuation line text_ points into
  size_t pos_ = 0;
  std::istream& input_;
  int& line_;
  const int first_line_;
};

bool bare_safe(const std::string& v) {
  if (v == "true" || v == "false") return true;
  for (const char c : v)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '+' && c != '-' && c != '_') return false;
  return parse_double(v).has_value() || parse_int(v).has_value();
}

std::string as_list(const std::vector<std::string>& values) {
  if (values.size() == 1) return ini_value(values[0]);
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + ini_value(values[i]);
  return out + "]";
}

// How a default is shown: one value, or a list for an option that takes several.
std::string shown_default(const CLI::Option& o) {
  const std::vector<std::string> values = default_values(o);
  return values.empty() ? "" : as_list(values);
}

std::string commented(const std::string& text) {
  std::string out = "# ";
  for (const char c : text) out += c == '\n' ? std::string("\n# ") : std::string(1, c);
  return out;
}

}  // namespace

ConfigLineError::ConfigLineError(int line, const std::string& reason)
    : CLI::ConfigError("line " + std::to_string(line) + ": " + reason), line_(line), reason_(reason) {}


std::vector<std::string> default_values(const CLI::Option& option) {
  std::string d = option.get_default_str();
  const bool bracketed = d.size() >= 2 && d.front() == '[' && d.back() == ']';
  if (bracketed) d = d.substr(1, d.size() - 2);
  if (d.empty()) return {};
  if (!bracketed && option.get_items_expected_max() <= 1) return {d};
  std::vector<std::string> parts;
  std::stringstream in(d);
  for (std::string part; std::getline(in, part, ',');) parts.emplace_back(trimmed(part));
  return parts;
}

std::string ini_value(const std::string& value) {
  return bare_safe(value) ? value : "\"" + escape_bytes(value, "\"\\") + "\"";
}

std::vector<CLI::ConfigItem> IniConfig::from_config(std::istream& input) const {
  std::vector<CLI::ConfigItem> read;
  std::map<const CLI::Option*, int> set_on_line;
  std::string raw;
  for (int number = 1; std::getline(input, raw); ++number) {
    std::string_view line = trimmed(raw);
    if (number == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line = trimmed(line.substr(3));  // a BOM
    if (line.empty() || line.front() == '#' || line.front() == ';') continue;
    if (line.front() == '[')
      throw ConfigLineError(number, "'" + std::string(line) + "': sections are not used, every key is a long option name");
    const size_t eq = line.find('=');
    std::string key(trimmed(line.substr(0, eq)));
    std::vector<std::string> values{"true"};  // a bare key sets a flag
    if (eq == std::string_view::npos) {
      const size_t comment = key.find(" #");
      if (comment != std::string::npos) key = std::string(trimmed(key.substr(0, comment)));
    }
    if (key.empty() || key.find_first_of(" \t\"'#") != std::string::npos)
      throw ConfigLineError(number, "expected KEY = VALUE, got '" + std::string(line) + "'");
    const int key_line = number;
    if (eq != std::string_view::npos) values = ValueParser(line.substr(eq + 1), input, number).parse();
    const CLI::Option* option = option_for(*app_, key);
    if (option == nullptr) throw ConfigLineError(key_line, "unknown key '" + key + "'");
    if (!option->get_configurable())
      throw ConfigLineError(key_line, "'" + key + "' cannot be set in a configuration file");
    const auto [it, fresh] = set_on_line.emplace(option, key_line);
    if (!fresh)
      throw ConfigLineError(key_line, "'" + key + "' is set again (first on line " + std::to_string(it->second) + ")");
    CLI::ConfigItem item;
    item.name = key;
    item.inputs = std::move(values);
    read.push_back(std::move(item));
  }
  return read;
}

std::string IniConfig::to_config(const CLI::App* app, bool, bool, std::string) const {
  std::ostringstream out;
  const std::string& name = app->get_name();
  out << commented(name + ": " + app->get_description()) << "\n"
      << "# Read back with " << name << " --config FILE. The options that were set are KEY = VALUE\n"
      << "# lines; every other option keeps its default, shown commented out (\"# KEY\" for a flag).\n";
  for (const CLI::Option* o : app->get_options()) {
    if (!o->get_configurable() || o == app->get_config_ptr()) continue;
    const std::string key = o->get_single_name();
    out << "\n";
    if (!o->get_description().empty()) out << commented(o->get_description()) << "\n";
    const bool flag = o->get_expected_max() == 0;
    if (o->count() == 0) {
      const std::string d = flag ? "" : shown_default(*o);
      out << "# " << key << (flag ? "" : d.empty() ? " =" : " = " + d) << "\n";
    } else if (flag && o->get_multi_option_policy() == CLI::MultiOptionPolicy::TakeAll) {
      int64_t count = 0;  // a counting flag (-v -v): its total, one value a file can hold
      for (const std::string& r : o->results()) count += CLI::detail::to_flag_value(r);
      out << key << " = " << count << "\n";
    } else if (flag) {
      out << key << " = " << ini_value(o->results().back()) << "\n";
    } else {
      // As typed if every value was seen before its transforms, else as CLI11 holds them.
      const std::vector<std::string>* values = &o->results();
      if (given_ != nullptr) {
        const auto typed = given_->find(o);
        if (typed != given_->end() && typed->second.size() == values->size()) values = &typed->second;
      }
      out << key << " = " << as_list(*values) << "\n";
    }
  }
  return out.str();
}

}  // namespace kestrel::cli
