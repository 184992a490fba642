// Tokenizer of the text loaders.
#include "token_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "fahr/geometry/load_error.h"

namespace fahr::geometry::detail {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

}  // namespace

TokenReader::TokenReader(std::string_view text, std::string_view file_name, char comment,
                         int first_line)
    : text_(text), file_name_(file_name), comment_(comment), line_(first_line) {}

void TokenReader::skip_space() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (is_space(c)) {
      ++pos_;
    } else if (comment_ != '\0' && c == comment_) {
      while (pos_ < text_.size() && text_[pos_] != '\n') {
        ++pos_;
      }
    } else {
      return;
    }
  }
}

bool TokenReader::next(Token& out) {
  skip_space();
  if (pos_ >= text_.size()) {
    return false;
  }
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_]) &&
         !(comment_ != '\0' && text_[pos_] == comment_)) {
    ++pos_;
  }
  out.text = text_.substr(start, pos_ - start);
  out.line = line_;
  last_token_line_ = line_;
  return true;
}

bool TokenReader::peek(Token& out) {
  skip_space();  // consuming whitespace does not change what the next token is
  const std::size_t saved_pos = pos_;
  const int saved_line = line_;
  const int saved_last = last_token_line_;
  const bool found = next(out);
  pos_ = saved_pos;
  line_ = saved_line;
  last_token_line_ = saved_last;
  return found;
}

Token TokenReader::expect(std::string_view what) {
  Token token;
  if (!next(token)) {
    fail(last_token_line_ > 0 ? last_token_line_ : line_,
         "unexpected end of file while reading " + std::string(what));
  }
  return token;
}

std::int64_t TokenReader::expect_int(std::string_view what) {
  const Token token = expect(what);
  std::int64_t value = 0;
  if (!parse_int(token.text, value)) {
    fail(token.line,
         "expected an integer for " + std::string(what) + ", found " + quote(token.text));
  }
  return value;
}

double TokenReader::expect_finite(std::string_view what) {
  const Token token = expect(what);
  double value = 0.0;
  if (!parse_double(token.text, value)) {
    fail(token.line, "expected a number for " + std::string(what) + ", found " + quote(token.text));
  }
  if (!std::isfinite(value)) {
    fail(token.line, "non-finite value " + quote(token.text) + " for " + std::string(what));
  }
  return value;
}

void TokenReader::expect_end_of_line(int line, std::string_view what) {
  Token token;
  if (peek(token) && token.line == line) {
    fail(line, "unexpected extra field " + quote(token.text) + " after " + std::string(what));
  }
}

void TokenReader::skip_line(int line) {
  Token token;
  while (peek(token) && token.line == line) {
    next(token);
  }
}

void TokenReader::skip_to(std::string_view keyword) {
  Token token;
  const int start_line = line_;
  while (next(token)) {
    if (token.text == keyword) {
      return;
    }
  }
  fail(start_line, "unexpected end of file: missing " + std::string(keyword));
}

void TokenReader::fail(int line, const std::string& message) const {
  throw LoadError(file_name_, line, message);
}

bool parse_int(std::string_view text, std::int64_t& value) {
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
  }
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  return result.ec == std::errc() && result.ptr == end && !text.empty();
}

bool parse_double(std::string_view text, double& value) {
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
  }
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  return result.ec == std::errc() && result.ptr == end && !text.empty();
}

std::string quote(std::string_view text) {
  constexpr std::size_t kMaxShown =
      40;  // long enough to recognise a token, short enough for one line
  std::string shown(text.substr(0, kMaxShown));
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) {
      c = '?';
    }
  }
  if (text.size() > kMaxShown) {
    shown += "...";
  }
  return "'" + shown + "'";
}

std::size_t reserve_bound(std::int64_t count, std::size_t remaining_bytes,
                          std::size_t min_bytes_per_record) {
  if (count <= 0) {
    return 0;
  }
  return std::min(static_cast<std::size_t>(count),
                  remaining_bytes / std::max<std::size_t>(min_bytes_per_record, 1) + 1);
}

}  // namespace fahr::geometry::detail
