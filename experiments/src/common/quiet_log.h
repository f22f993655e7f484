#pragma once
// The log of a --quiet run: only the lines that need the user (errors and
// warnings, with their indented continuation lines) reach the terminal; the
// set-up lines, the time-step audit and the summary stay out (results.json and
// the exit code hold the outcome). Internal.
#include <ostream>
#include <streambuf>
#include <string>

namespace rocklab::experiments::detail {

class QuietLogBuffer : public std::streambuf {
 public:
  explicit QuietLogBuffer(std::ostream& to) : to_(to) {}
  ~QuietLogBuffer() override { endLine(); }
  QuietLogBuffer(const QuietLogBuffer&) = delete;
  QuietLogBuffer& operator=(const QuietLogBuffer&) = delete;

  /// Whether `line` is passed on: it starts with "error" or "warning" (after
  /// spaces or "rocklab: "), or it is indented and follows a line passed on.
  static bool needsTheUser(const std::string& line, bool after_kept) {
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos) return false;
    if (start > 0 && after_kept) return true;
    std::string text = line.substr(start);
    if (text.rfind("rocklab: ", 0) == 0) text = text.substr(9);
    return text.rfind("error", 0) == 0 || text.rfind("warning", 0) == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    line_ += traits_type::to_char_type(c);
    if (c == '\n') endLine();
    return c;
  }
  int sync() override {
    to_.flush();
    return 0;
  }

 private:
  void endLine() {
    if (line_.empty()) return;
    kept_ = needsTheUser(line_, kept_);
    if (kept_) to_ << line_ << std::flush;
    line_.clear();
  }
  std::ostream& to_;
  std::string line_;
  bool kept_ = false;
};

}  // namespace rocklab::experiments::detail
