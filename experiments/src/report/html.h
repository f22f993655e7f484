#pragma once
// The pieces every report page is made of (run, sweep, study, calibration): text
// escaped for HTML, relative links percent-encoded, tables, figures, the list of
// a folder's files, and one page with its stylesheet inline (no network: the
// folder can be zipped and mailed). Internal to rocklab_experiments.
#include <filesystem>
#include <string>
#include <vector>

namespace rocklab::experiments::detail {

/// Text for an HTML element or attribute: & < > " ' escaped, bytes that are not
/// UTF-8 (a file name from another system) shown as U+FFFD.
std::string htmlText(const std::string& text);
/// A relative link to `relative` (a path inside the page's folder): every byte
/// outside A-Z a-z 0-9 - . _ ~ / percent-encoded.
std::string hrefOf(const std::filesystem::path& relative);
/// <a href="relative">text</a>.
std::string link(const std::filesystem::path& relative, const std::string& text);
/// A number as a page shows it: 4 significant digits, or "—" when not finite.
std::string shortNumber(double v);

/// The regular files of `dir` (not its subfolders) whose names end in `extension`, by name.
std::vector<std::filesystem::path> filesWithExtension(const std::filesystem::path& dir, const std::string& extension);

/// A table; cells are HTML already (escape text with htmlText).
std::string htmlTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
/// A figure: the image, its caption, and links to the files of the same stem
/// beside it that hold the plot otherwise (.svg, .pdf, and its data .plot.csv: plot.h).
std::string htmlFigure(const std::filesystem::path& dir, const std::filesystem::path& png, const std::string& caption);
/// Every file under `dir` (recursively), each linked with its size; a subfolder
/// folded (<details>) under its name and file count.
std::string htmlFileList(const std::filesystem::path& dir);

/// A whole page: <!DOCTYPE html>, its title, the stylesheet and `body`. Written so
/// that it is also well-formed XML (void elements closed with "/>"), which tests check.
std::string htmlPage(const std::string& title, const std::string& body);
/// <section> with a heading.
std::string htmlSection(const std::string& heading, const std::string& content);

}  // namespace rocklab::experiments::detail
