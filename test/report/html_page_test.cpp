// The self-contained report page: base64 on RFC 4648's own examples, images embedded by
// relative path only, missing ones named, the Markdown's tables and code rendered.

#include "tools/report/html_page.h"

#include <gtest/gtest.h>

#include <map>

namespace kestrel::report {
namespace {

TEST(Base64, Rfc4648TestVectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\xfe", 3)), "/wD+");  // the high digits, a zero byte
}

TEST(ImageMimeType, ByExtension) {
  EXPECT_EQ(image_mime_type("a/b.PNG"), "image/png");
  EXPECT_EQ(image_mime_type("x.jpeg"), "image/jpeg");
  EXPECT_EQ(image_mime_type("x.svg"), "image/svg+xml");
  EXPECT_EQ(image_mime_type("x.txt"), "");
  EXPECT_EQ(image_mime_type("noext"), "");
}

TEST(RenderPage, EmbedsTheImagesItNamesAndRendersTablesAndCode) {
  const std::map<std::string, std::string> files = {{"vo.png", "foo"}, {"flights/room pair.png", "foobar"}};
  std::vector<std::string> asked;
  const ReadFile read = [&](const std::string& path) -> std::optional<std::string> {
    asked.push_back(path);
    const auto it = files.find(path);
    return it == files.end() ? std::nullopt : std::optional<std::string>(it->second);
  };
  const std::string md =
      "# kestrel demo\n\n| metric | VO |\n|---|---|\n| ATE (m) | 0.0039 |\n\n"
      "```\nkestrel-vo: info: 601 frames <ok>\n```\n\n"
      "![vo](vo.png) ![pair](flights/room%20pair.png) ![gone](missing.png)\n"
      "![web](https://example.org/x.png) ![abs](/etc/x.png) ![other](plot.webp)\n";
  const HtmlPage page = render_page(md, "kestrel <demo>", read);

  EXPECT_NE(page.html.find("<title>kestrel &lt;demo&gt;</title>"), std::string::npos);
  EXPECT_NE(page.html.find("<table>"), std::string::npos) << page.html;
  EXPECT_NE(page.html.find("<td>0.0039</td>"), std::string::npos) << page.html;
  EXPECT_NE(page.html.find("601 frames &lt;ok&gt;"), std::string::npos) << page.html;  // code escaped
  EXPECT_NE(page.html.find("src=\"data:image/png;base64,Zm9v\""), std::string::npos) << page.html;
  EXPECT_NE(page.html.find("src=\"data:image/png;base64,Zm9vYmFy\""), std::string::npos) << page.html;
  EXPECT_NE(page.html.find("src=\"missing.png\""), std::string::npos);  // kept as a link
  EXPECT_NE(page.html.find("src=\"https://example.org/x.png\""), std::string::npos);
  EXPECT_NE(page.html.find("src=\"/etc/x.png\""), std::string::npos);
  EXPECT_NE(page.html.find("src=\"plot.webp\""), std::string::npos);  // a type not embedded: a link, not missing
  EXPECT_EQ(page.embedded, (std::vector<std::string>{"vo.png", "flights/room pair.png"}));
  EXPECT_EQ(page.missing, (std::vector<std::string>{"missing.png"}));
  // Only relative paths are looked up: never a URL or an absolute path.
  EXPECT_EQ(asked, (std::vector<std::string>{"vo.png", "flights/room pair.png", "missing.png"}));
  EXPECT_EQ(page.html.rfind("</html>\n"), page.html.size() - 8);
}

}  // namespace
}  // namespace kestrel::report
