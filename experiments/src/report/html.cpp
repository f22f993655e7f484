#include "report/html.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <system_error>

namespace rocklab::experiments::detail {

namespace fs = std::filesystem;

namespace {

/// Length of the UTF-8 sequence starting at s[i], or 0 when it is not one.
std::size_t utf8Length(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(i + k) >> 6) != 0x2) return 0;
  return n;
}

std::string humanSize(std::uintmax_t bytes) {
  char buf[32];
  if (bytes < 1024) std::snprintf(buf, sizeof buf, "%ju B", bytes);
  else if (bytes < 1024 * 1024) std::snprintf(buf, sizeof buf, "%.1f KiB", static_cast<double>(bytes) / 1024.0);
  else std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return buf;
}

std::uintmax_t sizeOf(const fs::path& p) {
  std::error_code ec;
  const std::uintmax_t n = fs::file_size(p, ec);
  return ec ? 0 : n;
}

/// Files of one folder, sorted; the page itself and half-written files left out.
std::vector<fs::directory_entry> entriesOf(const fs::path& dir) {
  std::vector<fs::directory_entry> entries;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) entries.push_back(*it);
  std::sort(entries.begin(), entries.end(),
            [](const fs::directory_entry& a, const fs::directory_entry& b) { return a.path() < b.path(); });
  return entries;
}

/// The list items of `dir`'s files, `prefix` being its path relative to the page; counts them.
std::string fileItems(const fs::path& dir, const fs::path& prefix, std::size_t& count) {
  std::string files, folders;
  for (const fs::directory_entry& e : entriesOf(dir)) {
    const fs::path name = e.path().filename();
    // The page itself (not yet written when a run lists its folder) and half-written files.
    if (name == "report.html" || name.extension() == ".partial") continue;
    std::error_code ec;
    if (e.is_directory(ec)) {
      std::size_t inside = 0;
      const std::string items = fileItems(e.path(), prefix / name, inside);
      count += inside;
      folders += "<li><details><summary>" + htmlText((prefix / name).string()) + "/ (" + std::to_string(inside) +
                 " files)</summary><ul>" + items + "</ul></details></li>\n";
    } else if (e.is_regular_file(ec)) {
      ++count;
      files += "<li>" + link(prefix / name, (prefix / name).string()) + " <span class=\"size\">" +
               humanSize(sizeOf(e.path())) + "</span></li>\n";
    }
  }
  return files + folders;
}

constexpr const char* kStyle = R"(
body { font-family: system-ui, sans-serif; margin: 0 auto; max-width: 72rem; padding: 1rem 2rem; color: #222; line-height: 1.4; }
h1 { font-size: 1.6rem; margin-bottom: 0.2rem; }
h2 { font-size: 1.2rem; border-bottom: 1px solid #ccc; padding-bottom: 0.2rem; margin-top: 2rem; }
table { border-collapse: collapse; margin: 0.5rem 0; }
th, td { border: 1px solid #ddd; padding: 0.25rem 0.6rem; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.status { display: inline-block; padding: 0.1rem 0.6rem; border-radius: 0.3rem; color: #fff; background: #2e7d32; }
.status.bad { background: #c62828; }
.failure { border: 2px solid #c62828; background: #fdecea; padding: 0.6rem 1rem; margin: 1rem 0; }
.warning { border: 1px solid #ef6c00; background: #fff3e0; padding: 0.4rem 1rem; margin: 0.5rem 0; }
figure { display: inline-block; margin: 0.5rem 1rem 1rem 0; vertical-align: top; }
figure img { max-width: min(100%, 36rem); border: 1px solid #ddd; }  /* full size one click away */
video { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9rem; color: #555; }
.bar { display: inline-block; height: 0.7rem; background: #0072b2; }
.size { color: #777; font-size: 0.85rem; }
ul.files { columns: 2; list-style: none; padding-left: 0; }
.muted { color: #777; }
)";

}  // namespace

std::string htmlText(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8Length(text, i);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
      continue;
    }
    if (n == 1) {
      const char c = text[i];
      switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        case '\'': out += "&#39;"; break;
        default:
          // Control characters other than tab and newline are not allowed in HTML (nor XML).
          if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n') out += "\xEF\xBF\xBD";
          else out += c;
      }
    } else {
      out.append(text, i, n);
    }
    i += n;
  }
  return out;
}

std::string hrefOf(const fs::path& relative) {
  static const char* const kHex = "0123456789ABCDEF";
  std::string out;
  for (const char ch : relative.generic_string()) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) != 0 && c < 0x80) out += ch;
    else if (ch == '-' || ch == '.' || ch == '_' || ch == '~' || ch == '/') out += ch;
    else out += std::string{'%', kHex[c >> 4], kHex[c & 15]};
  }
  return out;
}

std::string link(const fs::path& relative, const std::string& text) {
  return "<a href=\"" + hrefOf(relative) + "\">" + htmlText(text) + "</a>";
}

std::string shortNumber(double v) {
  if (!std::isfinite(v)) return "—";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::vector<fs::path> filesWithExtension(const fs::path& dir, const std::string& extension) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec) && it->path().extension() == extension) files.push_back(it->path().filename());
  std::sort(files.begin(), files.end());
  return files;
}

std::string htmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::string t = "<table>\n<tr>";
  for (const std::string& h : header) t += "<th>" + h + "</th>";
  t += "</tr>\n";
  for (const auto& row : rows) {
    t += "<tr>";
    for (const std::string& c : row) t += "<td>" + c + "</td>";
    t += "</tr>\n";
  }
  return t + "</table>\n";
}

std::string htmlFigure(const fs::path& dir, const fs::path& png, const std::string& caption) {
  std::string others;
  for (const auto& [ext, what] : {std::pair{".svg", "SVG"}, std::pair{".pdf", "PDF"}, std::pair{".plot.csv", "data"}}) {
    fs::path other = png;
    other.replace_extension(ext);
    if (fs::exists(dir / other)) others += " " + link(other, what);
  }
  return "<figure><a href=\"" + hrefOf(png) + "\"><img src=\"" + hrefOf(png) + "\" alt=\"" + htmlText(caption) +
         "\" /></a><figcaption>" + htmlText(caption) + (others.empty() ? "" : " —" + others) +
         "</figcaption></figure>\n";
}

std::string htmlFileList(const fs::path& dir) {
  std::size_t count = 0;
  const std::string items = fileItems(dir, {}, count);
  return "<p>" + std::to_string(count) + " files in this folder.</p>\n<ul class=\"files\">\n" + items + "</ul>\n";
}

std::string htmlPage(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\" />\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\" />\n<title>" +
         htmlText(title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n" + body +
         "<p class=\"muted\">Written by rocklab; rebuild with <code>rocklab report FOLDER</code>.</p>\n</body>\n</html>\n";
}

std::string htmlSection(const std::string& heading, const std::string& content) {
  return "<section>\n<h2>" + htmlText(heading) + "</h2>\n" + content + "</section>\n";
}

}  // namespace rocklab::experiments::detail
