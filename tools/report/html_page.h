#pragma once
// A Markdown report as one HTML page that needs no other file: rendered by md4c (GitHub's
// dialect: tables, fenced code, autolinks), with every image the report names by a relative
// path read and embedded as a data: URI, and a small style sheet inline. So the page can be
// mailed, attached to an issue or opened from anywhere, and still shows its figures.
//
// Invariants: the output is the md4c rendering, changed only in the src of <img> elements
// whose image was found (embedded) and by the page's head and foot. Raw HTML passes through
// as md4c passes it, so a raw <img src="..."> (src first) is embedded too. Absolute paths,
// URLs and files of other types (not a PNG, JPEG, SVG or GIF) are left as links.

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace kestrel::report {

/// The bytes of the file a relative path names (relative to the report), or nothing.
using ReadFile = std::function<std::optional<std::string>(const std::string& relative_path)>;

struct HtmlPage {
  std::string html;
  std::vector<std::string> embedded;  ///< images put in the page, as the report names them
  std::vector<std::string> missing;   ///< images it would embed but could not read (kept as links)
};

/// `markdown` rendered as a page titled `title`. Throws std::runtime_error if md4c fails.
HtmlPage render_page(const std::string& markdown, const std::string& title, const ReadFile& read_file);

/// RFC 4648 base64 of `bytes`, with padding.
std::string base64(const std::string& bytes);

/// The MIME type of an image file by its extension ("image/png"), or "" if not an image kestrel writes.
std::string image_mime_type(const std::string& path);

}  // namespace kestrel::report
