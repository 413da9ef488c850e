#include "drivers/tum/tum_lists.h"

#include <cmath>
#include <fstream>

#include "common/error.h"
#include "common/text.h"
#include "common/time.h"

namespace kestrel::tum {
namespace {

// Calls `on_line(fields, line_no, line)` for every line that is neither blank nor a comment.
template <class OnLine>
void for_each_data_line(const std::string& path, const char* what, OnLine on_line) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open " + what);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (is_comment_or_blank(line)) continue;
    on_line(split_fields(line), line_no, line);
  }
  if (in.bad()) throw InputError(path + ": read error");
}

int64_t parse_stamp(const std::string& path, int line_no, std::string_view token,
                    int64_t previous, bool has_previous) {
  const auto utime = parse_seconds(token);
  if (!utime) {
    throw InputError(at_line(path, line_no, "bad timestamp '" + std::string(token) + "'"));
  }
  if (has_previous && *utime <= previous) {
    throw InputError(at_line(path, line_no, "timestamp " + std::string(token) +
                                                " is not after the previous one (" +
                                                format_seconds(previous) + ")"));
  }
  return *utime;
}

}  // namespace

std::vector<ImageEntry> read_image_list(const std::string& path) {
  std::vector<ImageEntry> entries;
  for_each_data_line(path, "image list",
                     [&](const std::vector<std::string_view>& f, int line_no, const std::string& line) {
                       if (f.size() != 2) {
                         throw InputError(at_line(
                             path, line_no, "expected 'timestamp filename', got '" + line + "'"));
                       }
                       const bool has_prev = !entries.empty();
                       const int64_t utime = parse_stamp(path, line_no, f[0],
                                                         has_prev ? entries.back().utime : 0, has_prev);
                       entries.push_back({utime, std::string(f[1]), line_no});
                     });
  if (entries.empty()) throw InputError(path + ": lists no images");
  return entries;
}

std::vector<AccelerometerSample> read_accelerometer(const std::string& path) {
  std::vector<AccelerometerSample> samples;
  for_each_data_line(
      path, "accelerometer log",
      [&](const std::vector<std::string_view>& f, int line_no, const std::string& line) {
        Eigen::Vector3d a;
        bool numbers = f.size() == 4;
        for (int i = 0; numbers && i < 3; ++i) {
          const auto v = parse_double(f[i + 1]);
          numbers = v.has_value();
          if (numbers) a[i] = *v;
        }
        if (!numbers) {
          throw InputError(at_line(path, line_no, "expected 'timestamp ax ay az', got '" + line + "'"));
        }
        if (!a.allFinite()) throw InputError(at_line(path, line_no, "non-finite acceleration"));
        const bool has_prev = !samples.empty();
        const int64_t utime =
            parse_stamp(path, line_no, f[0], has_prev ? samples.back().utime : 0, has_prev);
        samples.push_back({utime, a});
      });
  return samples;
}

}  // namespace kestrel::tum
