#include "tools/report/html_page.h"

#include <md4c-html.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace kestrel::report {
namespace {

// Enough to read tables and code on a screen and in print; nothing fetched from elsewhere.
constexpr const char* kStyle = R"(body{font-family:system-ui,sans-serif;max-width:72rem;margin:2rem auto;padding:0 1rem;line-height:1.45;color:#222}
h1,h2,h3{line-height:1.2}h2{border-bottom:1px solid #ddd;padding-bottom:.2rem;margin-top:2rem}
table{border-collapse:collapse;margin:1rem 0;font-size:.9rem}th,td{border:1px solid #ccc;padding:.25rem .5rem;text-align:right}
th:first-child,td:first-child{text-align:left}tr:nth-child(even){background:#f6f6f6}
pre{background:#f4f4f4;padding:.6rem;overflow-x:auto;font-size:.8rem;line-height:1.3}
code{font-family:ui-monospace,monospace}img{max-width:100%;height:auto;vertical-align:top;margin:.3rem 0})";

void append(const MD_CHAR* text, MD_SIZE size, void* out) { static_cast<std::string*>(out)->append(text, size); }

std::string escape_html(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
}

// md4c writes a link's URL percent-encoded and with '&' as "&amp;": back to the file's name.
std::string url_to_path(const std::string& url) {
  std::string s;
  for (size_t i = 0; i < url.size(); ++i) {
    if (url[i] == '%' && i + 2 < url.size() && hex_value(url[i + 1]) >= 0 && hex_value(url[i + 2]) >= 0) {
      s += static_cast<char>(16 * hex_value(url[i + 1]) + hex_value(url[i + 2]));
      i += 2;
    } else if (url.compare(i, 5, "&amp;") == 0) {
      s += '&';
      i += 4;
    } else {
      s += url[i];
    }
  }
  return s;
}

bool is_relative_path(const std::string& path) {
  if (path.empty() || path.front() == '/' || path.front() == '#') return false;
  const size_t colon = path.find(':');
  const size_t slash = path.find('/');
  return colon == std::string::npos || (slash != std::string::npos && slash < colon);  // no scheme
}

}  // namespace

std::string base64(const std::string& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const uint32_t v = static_cast<uint32_t>(static_cast<unsigned char>(bytes[i])) << 16 |
                       static_cast<uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8 |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kDigits[(v >> (6 * k)) & 63];
  }
  const size_t rest = bytes.size() - i;
  if (rest > 0) {
    uint32_t v = static_cast<uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (rest == 2) v |= static_cast<uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += rest == 2 ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string image_mime_type(const std::string& path) {
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == "png") return "image/png";
  if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
  if (ext == "svg") return "image/svg+xml";
  if (ext == "gif") return "image/gif";
  return "";
}

HtmlPage render_page(const std::string& markdown, const std::string& title, const ReadFile& read_file) {
  std::string body;
  if (md_html(markdown.data(), static_cast<MD_SIZE>(markdown.size()), append, &body, MD_DIALECT_GITHUB,
              MD_HTML_FLAG_SKIP_UTF8_BOM) != 0)
    throw std::runtime_error("the Markdown could not be rendered (md4c failed)");

  HtmlPage page;
  std::string out;
  const std::string marker = "<img src=\"";
  size_t at = 0;
  for (size_t found; (found = body.find(marker, at)) != std::string::npos;) {
    const size_t start = found + marker.size();
    const size_t end = body.find('"', start);
    if (end == std::string::npos) break;
    out.append(body, at, start - at);
    const std::string url = body.substr(start, end - start);
    const std::string path = url_to_path(url);
    const std::string mime = image_mime_type(path);
    std::optional<std::string> bytes;
    const bool embeddable = is_relative_path(path) && !mime.empty();
    if (embeddable) bytes = read_file(path);
    if (bytes) {
      out += "data:" + mime + ";base64," + base64(*bytes);
      page.embedded.push_back(path);
    } else {
      out += url;
      if (embeddable) page.missing.push_back(path);
    }
    at = end;
  }
  out.append(body, at, std::string::npos);

  page.html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
              escape_html(title) + "</title>\n<style>\n" + kStyle + "\n</style>\n</head>\n<body>\n" + out +
              "</body>\n</html>\n";
  return page;
}

}  // namespace kestrel::report
