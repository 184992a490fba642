// Whitespace-separated tokens with their line numbers, for the text loaders:
// every parse error can then name the file and the line.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace fahr::geometry::detail {

struct Token {
  std::string_view text;
  int line = 0;  // 1-based
};

class TokenReader {
 public:
  // comment: a character that starts a comment running to the end of the line, or '\0' for none.
  // first_line: the line number of the first character of text (a caller
  // may have consumed header lines itself).
  TokenReader(std::string_view text, std::string_view file_name, char comment, int first_line = 1);

  // False at the end of the input.
  bool next(Token& out);
  bool peek(Token& out);
  // The next token; a LoadError "unexpected end of file while reading <what>" when there is none.
  Token expect(std::string_view what);
  std::int64_t expect_int(std::string_view what);
  double expect_finite(std::string_view what);
  // Checks the next token is on a later line than `line` (or there is none):
  // catches records with more fields than their header announced.
  void expect_end_of_line(int line, std::string_view what);
  // Skips the tokens left on `line` (fields a format allows but fahr ignores).
  void skip_line(int line);
  // Skips tokens up to and including `keyword` (e.g. "$EndComments").
  void skip_to(std::string_view keyword);
  // Bytes not yet read: an upper bound for what a count in a header can mean.
  std::size_t remaining_bytes() const { return text_.size() - pos_; }
  int line() const { return line_; }
  std::string_view file_name() const { return file_name_; }

  [[noreturn]] void fail(int line, const std::string& message) const;

 private:
  void skip_space();

  std::string_view text_;
  std::string_view file_name_;
  char comment_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int last_token_line_ = 0;  // where an unexpected end of file is reported
};

// Strict parses of a whole token (no trailing characters); false on failure.
bool parse_int(std::string_view text, std::int64_t& value);
bool parse_double(std::string_view text, double& value);
// Shortens a token for an error message, so a garbage megabyte stays readable.
std::string quote(std::string_view text);
// Caps a count from a header by what the rest of the file can hold, so a
// corrupt header cannot make a loader reserve terabytes.
std::size_t reserve_bound(std::int64_t count, std::size_t remaining_bytes,
                          std::size_t min_bytes_per_record);

}  // namespace fahr::geometry::detail
