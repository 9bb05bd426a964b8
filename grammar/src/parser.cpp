// The OpenSYMORO grammars. A line-oriented driver splits a file into lines and decides what each
// line is (title, table header, table row, equation, .par entry); Boost.Spirit X3 parses the
// inside of each line. Expressions are built on an explicit operand stack by semantic actions,
// so the X3 parsers carry no attributes and every failure is thrown as a ParseError by the
// `expect` and `nest` parsers below, with the position where the input went wrong.
#include "symoro/grammar/parser.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <system_error>
#include <utility>

#include <boost/spirit/home/x3.hpp>

namespace symoro::grammar {

namespace {

// Replaces control characters so that what() stays one readable line of source; every byte
// keeps its column so the caret below it still points at the right place.
std::string printable_line(const std::string& line) {
  std::string out = line;
  for (char& c : out) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\t') || u == 0x7f) c = '?';
  }
  return out;
}

std::string format_error(const std::string& file, int line, int column, const std::string& message,
                         const std::string& source_line) {
  if (line <= 0) return file + ": error: " + message;
  std::string out = file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message + "\n" +
                    printable_line(source_line) + "\n";
  // Copy tabs from the source line so the caret lines up however the terminal expands them.
  const auto indent = static_cast<std::size_t>(std::max(column - 1, 0));
  for (std::size_t i = 0; i < indent; ++i) out += i < source_line.size() && source_line[i] == '\t' ? '\t' : ' ';
  return out + "^";
}

}  // namespace

ParseError::ParseError(std::string file, int line, int column, std::string message, std::string source_line)
    : std::runtime_error(format_error(file, line, column, message, source_line)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      message_(std::move(message)) {}

namespace {

namespace x3 = boost::spirit::x3;
using Iterator = const char*;

// Deepest expression tree accepted. Nesting (kMaxExpressionDepth) bounds the parser's own
// recursion; this bounds the tree's height, which a long chain like `a+b+c+...` also grows, so
// that destroying, evaluating or compiling any parsed expression recurses a bounded depth.
constexpr int kMaxTreeHeight = 1024;

std::string describe_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7f) return std::string("'") + c + "'";
  char buf[8];
  std::snprintf(buf, sizeof buf, "'\\x%02X'", u);
  return buf;
}

// Characters that may appear in an expression, equation, table row or .par entry; anything else
// is reported as an unexpected character rather than as a missing token.
bool is_token_char(char c) {
  if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return true;
  return std::string_view("_.+-*/(),=;{} \t").find(c) != std::string_view::npos;
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// One line of the text being parsed, without its line break.
struct Line {
  Iterator begin;
  Iterator end;
  std::string_view text() const { return {begin, static_cast<std::size_t>(end - begin)}; }
};

// The text being parsed, split into lines, and the conversion of a character's address to a
// line and column. `parsed` is the buffer the parsers read: the original text or a copy of the
// same length (the .par parser blanks comments out in a copy).
class Source {
 public:
  Source(std::string_view original, Iterator parsed, std::string path)
      : original_(original), parsed_(parsed), path_(std::move(path)) {
    std::size_t start = 0;
    while (true) {
      const auto nl = original.find('\n', start);
      const std::size_t stop = nl == std::string_view::npos ? original.size() : nl;
      std::size_t end = stop;
      if (end > start && original[end - 1] == '\r') --end;
      lines_.push_back({parsed + start, parsed + end});
      if (nl == std::string_view::npos) break;
      start = nl + 1;
    }
    // A final line break ends the last line rather than starting an empty one.
    if (lines_.size() > 1 && lines_.back().begin == parsed + original.size()) lines_.pop_back();
  }

  const std::string& path() const { return path_; }
  const std::vector<Line>& lines() const { return lines_; }

  Position position(Iterator p) const {
    // Parsing goes line by line, so the line of the previous lookup is the usual answer.
    const bool on_hint = lines_[hint_].begin <= p && (hint_ + 1 == lines_.size() || p < lines_[hint_ + 1].begin);
    if (!on_hint) {
      const auto next =
          std::upper_bound(lines_.begin(), lines_.end(), p, [](Iterator q, const Line& l) { return q < l.begin; });
      hint_ = static_cast<std::size_t>(next - lines_.begin()) - 1;
    }
    return {static_cast<int>(hint_) + 1, static_cast<int>(p - lines_[hint_].begin) + 1};
  }

  [[noreturn]] void fail(Iterator at, const std::string& message) const {
    const Position p = position(at);
    const Line& line = lines_[static_cast<std::size_t>(p.line) - 1];
    const auto offset = static_cast<std::size_t>(line.begin - parsed_);
    const auto length = static_cast<std::size_t>(line.end - line.begin);
    throw ParseError(path_, p.line, p.column, message, std::string(original_.substr(offset, length)));
  }

  // `at` is where a parser wanted `what`; `last` ends the text it was given.
  [[noreturn]] void expected(Iterator at, Iterator last, const char* what) const {
    if (at != last && !is_token_char(*at)) fail(at, "unexpected character " + describe_char(*at));
    fail(at, std::string("expected ") + what);
  }

  // Just past the last non-blank character: where a missing end marker is reported.
  Iterator end_of_content() const {
    for (auto it = lines_.rbegin(); it != lines_.rend(); ++it)
      if (!trim(it->text()).empty()) return it->begin + it->text().find_last_not_of(" \t") + 1;
    return lines_.front().begin;
  }

  // These are text files: control characters other than tab and line breaks (a NUL byte, a
  // lone carriage return) are errors wherever they stand.
  void check_characters() const {
    for (std::size_t i = 0; i < original_.size(); ++i) {
      const char c = original_[i];
      const auto u = static_cast<unsigned char>(c);
      if (c == '\n' || c == '\t') continue;
      if (c == '\r' && (i + 1 == original_.size() || original_[i + 1] == '\n')) continue;
      if (u < 0x20 || u == 0x7f) fail(parsed_ + i, "unexpected character " + describe_char(c));
    }
  }

  bool blank() const { return original_.find_first_not_of(" \t\r\n") == std::string_view::npos; }

 private:
  std::string_view original_;
  Iterator parsed_;
  std::string path_;
  std::vector<Line> lines_;
  mutable std::size_t hint_ = 0;
};

// An expression under construction, with the height of its tree and where it starts.
struct Node {
  Expr expr;
  int height = 1;
  Iterator begin = nullptr;
};

// The state the X3 semantic actions work on (reached through x3::with<builder_tag>).
struct Builder {
  explicit Builder(const Source& s) : source(s) {}

  const Source& source;
  std::vector<Node> stack;           // finished operands
  std::vector<std::size_t> calls;    // stack size at the '(' of each open function call
  int depth = 0;                     // current nesting of parentheses, unary signs and powers
  std::vector<std::string> columns;  // a table header's names
  std::vector<Iterator> column_at;
  std::string_view name;  // the NAME of an equation or .par entry
  Iterator name_at = nullptr;
  bool is_list = false;  // the .par value was `{...}`

  void reset() {
    stack.clear();
    calls.clear();
    depth = 0;
    columns.clear();
    column_at.clear();
    is_list = false;
  }

  Node pop() {
    Node n = std::move(stack.back());
    stack.pop_back();
    return n;
  }

  void push(Expr::Kind kind, Iterator begin, std::vector<Node> operands, Iterator report_at) {
    Node n;
    n.expr.kind = kind;
    n.expr.at = source.position(begin);
    n.begin = begin;
    for (Node& operand : operands) {
      n.height = std::max(n.height, operand.height + 1);
      n.expr.args.push_back(std::move(operand.expr));
    }
    if (n.height > kMaxTreeHeight)
      source.fail(report_at, "expression more than " + std::to_string(kMaxTreeHeight) + " operations deep");
    stack.push_back(std::move(n));
  }

  void push_number(Iterator first, Iterator last) {
    double value = 0;
    const auto [end, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || end != last || !std::isfinite(value)) source.fail(first, "number out of range");
    push(Expr::Kind::Number, first, {}, first);
    stack.back().expr.number = value;
  }

  void push_symbol(Iterator first, Iterator last) {
    push(Expr::Kind::Symbol, first, {}, first);
    stack.back().expr.name.assign(first, last);
  }

  void negate(Iterator begin) {
    std::vector<Node> operand;
    operand.push_back(pop());
    push(Expr::Kind::Negate, begin, std::move(operand), begin);
  }

  void binary(Expr::Kind kind) {
    std::vector<Node> operands(2);
    operands[1] = pop();
    operands[0] = pop();
    Iterator const begin = operands[0].begin;
    Iterator const rhs = operands[1].begin;
    push(kind, begin, std::move(operands), rhs);
  }

  // `+x` and `(x)` keep x's tree but start where the sign or parenthesis does.
  void starts_at(Iterator begin) {
    stack.back().begin = begin;
    stack.back().expr.at = source.position(begin);
  }

  void finish_call() {
    const std::size_t mark = calls.back();
    calls.pop_back();
    const auto first_arg = stack.begin() + static_cast<std::ptrdiff_t>(mark);
    std::vector<Node> args(std::make_move_iterator(first_arg), std::make_move_iterator(stack.end()));
    stack.resize(mark);
    Node function = pop();
    push(Expr::Kind::Call, function.begin, std::move(args), function.begin);
    stack.back().expr.name = std::move(function.expr.name);
  }
};

struct builder_tag;

template <typename Context>
Builder& builder(const Context& ctx) {
  return x3::get<builder_tag>(ctx);
}

// `expect(p, "x")` matches p or throws "expected x" where p should have started.
template <typename Subject>
struct expect_parser : x3::parser<expect_parser<Subject>> {
  using attribute_type = x3::unused_type;
  static bool const has_attribute = false;

  constexpr expect_parser(const Subject& s, const char* w) : subject(s), what(w) {}

  template <typename It, typename Context, typename RContext, typename Attribute>
  bool parse(It& first, const It& last, const Context& ctx, RContext& rctx, Attribute&) const {
    if (subject.parse(first, last, ctx, rctx, x3::unused)) return true;
    x3::skip_over(first, last, ctx);
    builder(ctx).source.expected(first, last, what);
  }

  Subject subject;
  const char* what;
};

template <typename P>
constexpr auto expect(const P& p, const char* what) {
  using Subject = typename x3::extension::as_parser<P>::value_type;
  return expect_parser<Subject>(x3::as_parser(p), what);
}

// `nest(open, body)`: after `open` matches, one level deeper for `body`. Every recursive path of
// the expression grammar goes through one, so this bounds the recursion of the parser.
template <typename Open, typename Body>
struct nest_parser : x3::parser<nest_parser<Open, Body>> {
  using attribute_type = x3::unused_type;
  static bool const has_attribute = false;

  constexpr nest_parser(const Open& o, const Body& b) : open(o), body(b) {}

  template <typename It, typename Context, typename RContext, typename Attribute>
  bool parse(It& first, const It& last, const Context& ctx, RContext& rctx, Attribute&) const {
    x3::skip_over(first, last, ctx);
    const It save = first;
    if (!open.parse(first, last, ctx, rctx, x3::unused)) return false;
    Builder& b = builder(ctx);
    if (b.depth == kMaxExpressionDepth)
      b.source.fail(save, "nesting deeper than " + std::to_string(kMaxExpressionDepth) + " levels");
    ++b.depth;
    const bool ok = body.parse(first, last, ctx, rctx, x3::unused);
    --b.depth;
    if (!ok) first = save;
    return ok;
  }

  Open open;
  Body body;
};

template <typename O, typename B>
constexpr auto nest(const O& o, const B& b) {
  using Open = typename x3::extension::as_parser<O>::value_type;
  using Body = typename x3::extension::as_parser<B>::value_type;
  return nest_parser<Open, Body>(x3::as_parser(o), x3::as_parser(b));
}

// ---- semantic actions -------------------------------------------------------------------------

const auto push_number = [](auto& ctx) {
  const auto& range = x3::_attr(ctx);
  builder(ctx).push_number(range.begin(), range.end());
};
const auto push_symbol = [](auto& ctx) {
  const auto& range = x3::_attr(ctx);
  builder(ctx).push_symbol(range.begin(), range.end());
};
const auto open_call = [](auto& ctx) {
  Builder& b = builder(ctx);
  b.calls.push_back(b.stack.size());
};
const auto close_call = [](auto& ctx) { builder(ctx).finish_call(); };
const auto negate = [](auto& ctx) { builder(ctx).negate(x3::_attr(ctx).begin()); };
const auto starts_here = [](auto& ctx) { builder(ctx).starts_at(x3::_attr(ctx).begin()); };

template <Expr::Kind kind>
const auto binary = [](auto& ctx) { builder(ctx).binary(kind); };

const auto set_name = [](auto& ctx) {
  Builder& b = builder(ctx);
  const auto& range = x3::_attr(ctx);
  b.name = std::string_view(range.begin(), static_cast<std::size_t>(range.size()));
  b.name_at = range.begin();
};
const auto add_column = [](auto& ctx) {
  Builder& b = builder(ctx);
  const auto& range = x3::_attr(ctx);
  b.columns.emplace_back(range.begin(), range.end());
  b.column_at.push_back(range.begin());
};
const auto set_list = [](auto& ctx) { builder(ctx).is_list = true; };

// ---- grammar ----------------------------------------------------------------------------------

const auto blank = x3::lit(' ') | '\t';
// Line breaks only matter to parse_expression, which may span lines.
const auto skipper = blank | '\r' | '\n';

const auto letter = x3::char_('a', 'z') | x3::char_('A', 'Z') | x3::char_('_');
const auto digit = x3::char_('0', '9');
const auto identifier = x3::raw[x3::lexeme[letter >> *(letter | digit)]];
const auto exponent = (x3::lit('e') | 'E') >> -(x3::lit('+') | '-') >> +digit;
const auto number = x3::raw[x3::lexeme[((+digit >> -('.' >> *digit)) | ('.' >> +digit)) >> -exponent]];

const x3::rule<class expr_rule> expr = "expression";
const x3::rule<class unary_rule> unary = "unary expression";

const auto arguments = -(expr >> *(',' >> expect(expr, "an argument after ','")));
const auto call_or_symbol = identifier[push_symbol] >>
                            -nest(x3::lit('(')[open_call],
                                  arguments >> expect(')', "')' after the function arguments"))[close_call];
const auto group = x3::raw[nest('(', expect(expr, "an expression after '('") >> expect(')', "')'"))][starts_here];
const auto primary = number[push_number] | call_or_symbol | group;

// Python precedence: `**` binds tighter than a sign on its left and takes a signed operand on
// its right (-x**2 is -(x**2), 2**-1 is 2**(-1)) and is right-associative.
const auto power = primary >> -nest("**", expect(unary, "an expression after '**'"))[binary<Expr::Kind::Power>];
const auto unary_def = x3::raw[nest('-', expect(unary, "an expression after '-'"))][negate] |
                       x3::raw[nest('+', expect(unary, "an expression after '+'"))][starts_here] | power;
const auto term = unary >> *(('*' >> expect(unary, "an expression after '*'"))[binary<Expr::Kind::Multiply>] |
                             ('/' >> expect(unary, "an expression after '/'"))[binary<Expr::Kind::Divide>]);
const auto expr_def = term >> *(('+' >> expect(term, "an expression after '+'"))[binary<Expr::Kind::Add>] |
                                ('-' >> expect(term, "an expression after '-'"))[binary<Expr::Kind::Subtract>]);

BOOST_SPIRIT_DEFINE(expr, unary)

const auto whole_expression = expect(expr, "an expression") >>
                              expect(x3::eoi, "an operator or the end of the expression");

const auto equation_line = expect(identifier[set_name], "an equation 'NAME = expression;' or '*=*'") >>
                           expect('=', "'=' after the name") >> expect(expr, "an expression after '='") >>
                           expect(';', "';' at the end of the equation") >>
                           expect(x3::eoi, "the end of the line after ';'");

const auto header_line = +identifier[add_column] >> expect(x3::eoi, "a column name");

// Cells are expressions without spaces: a space ends a cell.
const auto row_line = *x3::lexeme[expr] >> expect(x3::eoi, "a space between cells or the end of the row");

const auto par_list = x3::lit('{')[set_list] >> -(expr >> *(',' >> expect(expr, "a value after ','"))) >>
                      expect('}', "',' or '}' in the list");
const auto par_line = expect(identifier[set_name], "'NAME = value'") >> expect('=', "'=' after the name") >>
                      expect(par_list | expr, "a value after '='") >>
                      expect(x3::eoi, "the end of the line after the value");

// The inside of `(* Robotname = 'planar2r' *)`; its attribute is the name.
const auto robotname_comment = *blank >> "Robotname" >> *blank >> '=' >> *blank >> '\'' >> *(x3::char_ - '\'') >>
                               '\'' >> *blank >> x3::eoi;

// Runs `grammar` over [first, last); every failure inside throws, so only success returns.
template <typename Grammar>
void run(Builder& b, const Grammar& grammar, Iterator first, Iterator last) {
  b.reset();
  x3::phrase_parse(first, last, x3::with<builder_tag>(b)[grammar], skipper);
}

Expr take_expr(Builder& b) { return std::move(b.stack.back().expr); }

// ---- model files ------------------------------------------------------------------------------

constexpr std::string_view kEquations = "Equations:";
constexpr std::string_view kEnd = "*=*";

std::string plural(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

bool is_header(std::string_view trimmed) {
  const auto word = trimmed.substr(0, trimmed.find_first_of(" \t"));
  return word == "j" || word == "axis";
}

class ModelParser {
 public:
  explicit ModelParser(const Source& source) : src_(source), lines_(source.lines()), b_(source) {}

  ModelFile parse() {
    ModelFile file;
    file.path = src_.path();
    if (src_.blank()) src_.fail(lines_.front().begin, "empty file");

    section(kEquations, file.title, file.tables, lines_.size());
    file.equations_at = at(i_);
    for (++i_;; ++i_) {
      if (i_ == lines_.size()) src_.fail(src_.end_of_content(), "missing '*=*' end marker");
      const auto t = text(i_);
      if (t.empty()) continue;
      if (t == kEnd) break;
      run(b_, equation_line, lines_[i_].begin, lines_[i_].end);
      Equation eq;
      eq.name = std::string(b_.name);
      eq.at = src_.position(b_.name_at);
      eq.value = take_expr(b_);
      file.equations.push_back(std::move(eq));
    }

    // regp.txt goes on with "Grouped inertial parameters", more tables and a second `*=*`.
    ++i_;
    if (!rest_is_blank()) {
      std::vector<std::string> grouped_title;
      section(kEnd, grouped_title, file.grouped_tables, 1);
      if (!grouped_title.empty()) file.grouped_title = grouped_title.front();
      ++i_;
      if (!rest_is_blank()) src_.fail(first_char(i_), "unexpected text after the final '*=*'");
    }
    return file;
  }

 private:
  std::string_view text(std::size_t i) const { return trim(lines_[i].text()); }
  Iterator first_char(std::size_t i) const { return text(i).data(); }
  Position at(std::size_t i) const { return src_.position(first_char(i)); }

  // Moves i_ to the next non-blank line; true when there is none.
  bool rest_is_blank() {
    while (i_ < lines_.size() && text(i_).empty()) ++i_;
    return i_ == lines_.size();
  }

  // A title is a line whose next non-blank line is a header row (starting with `j` or `axis`).
  bool is_title(std::size_t i) const {
    for (std::size_t k = i + 1; k < lines_.size(); ++k) {
      const auto t = text(k);
      if (!t.empty()) return is_header(t);
    }
    return false;
  }

  // Free-text lines (at most `max_free`, before the first table) and tables, up to the line
  // `marker`; leaves i_ on the marker.
  void section(std::string_view marker, std::vector<std::string>& free_lines, std::vector<Table>& tables,
               std::size_t max_free) {
    for (;;) {
      if (i_ == lines_.size())
        src_.fail(src_.end_of_content(), marker == kEnd ? "missing '*=*' end marker" : "missing 'Equations:' section");
      const auto t = text(i_);
      if (t.empty()) {
        ++i_;
      } else if (t == marker) {
        return;
      } else if (t == kEnd || t == kEquations) {
        src_.fail(first_char(i_), "expected '" + std::string(marker) + "' before '" + std::string(t) + "'");
      } else if (is_title(i_)) {
        tables.push_back(table(marker));
      } else if (is_header(t)) {
        src_.fail(first_char(i_), "table header without a title line");
      } else if (tables.empty() && free_lines.size() < max_free) {
        free_lines.emplace_back(t);
        ++i_;
      } else {
        src_.fail(first_char(i_),
                  "expected a table (a title line, then a header row starting with 'j' or "
                  "'axis') or '" +
                      std::string(marker) + "'");
      }
    }
  }

  Table table(std::string_view marker) {
    Table table;
    table.title = std::string(text(i_));
    table.at = at(i_);
    do ++i_;
    while (text(i_).empty());  // is_title() saw the header ahead

    run(b_, header_line, lines_[i_].begin, lines_[i_].end);
    std::set<std::string_view> seen;
    for (std::size_t c = 0; c < b_.columns.size(); ++c)
      if (!seen.insert(b_.columns[c]).second) src_.fail(b_.column_at[c], "duplicate column '" + b_.columns[c] + "'");
    table.columns = std::move(b_.columns);

    for (++i_; i_ < lines_.size(); ++i_) {
      const auto t = text(i_);
      if (t.empty() || t == marker || t == kEnd || t == kEquations || is_title(i_)) break;
      run(b_, row_line, lines_[i_].begin, lines_[i_].end);
      const std::size_t cells = b_.stack.size();
      const std::size_t columns = table.columns.size();
      if (cells != columns) {
        const Iterator where = cells > columns ? b_.stack[columns].begin : t.data() + t.size();
        src_.fail(where, "row has " + plural(cells, "cell") + " but the header has " + plural(columns, "column"));
      }
      Table::Row row;
      row.at = at(i_);
      for (Node& n : b_.stack) row.cells.push_back(std::move(n.expr));
      table.rows.push_back(std::move(row));
    }
    return table;
  }

  const Source& src_;
  const std::vector<Line>& lines_;
  Builder b_;
  std::size_t i_ = 0;
};

// ---- .par files -------------------------------------------------------------------------------

// Blanks out `(* ... *)` comments (not nested) in `text`, keeping line breaks so positions do
// not move, and returns the name of the first `(* Robotname = 'x' *)` comment.
std::string blank_comments(const Source& src, std::string& text) {
  std::string robot_name;
  std::size_t pos = 0;
  while ((pos = text.find("(*", pos)) != std::string::npos) {
    const auto close = text.find("*)", pos + 2);
    if (close == std::string::npos) src.fail(text.data() + pos, "unterminated comment: expected '*)'");
    const char* first = text.data() + pos + 2;
    const char* last = text.data() + close;
    std::string name;
    if (robot_name.empty() && x3::parse(first, last, robotname_comment, name)) robot_name = name;
    for (auto k = pos; k < close + 2; ++k)
      if (text[k] != '\n' && text[k] != '\r') text[k] = ' ';
    pos = close + 2;
  }
  return robot_name;
}

}  // namespace

ModelFile parse_model_file(std::string_view text, const std::string& path) {
  const Source source(text, text.data(), path);
  source.check_characters();
  return ModelParser(source).parse();
}

ParFile parse_par_file(std::string_view text, const std::string& path) {
  std::string cleaned(text);
  const Source source(text, cleaned.data(), path);
  source.check_characters();
  if (source.blank()) source.fail(source.lines().front().begin, "empty file");

  ParFile file;
  file.path = path;
  file.robot_name = blank_comments(source, cleaned);
  Builder b(source);
  for (const Line& line : source.lines()) {
    if (trim(line.text()).empty()) continue;
    run(b, par_line, line.begin, line.end);
    ParEntry entry;
    entry.name = std::string(b.name);
    entry.at = source.position(b.name_at);
    entry.is_list = b.is_list;
    for (Node& n : b.stack) entry.values.push_back(std::move(n.expr));
    file.entries.push_back(std::move(entry));
  }
  return file;
}

Expr parse_expression(std::string_view text, const std::string& path) {
  const Source source(text, text.data(), path);
  source.check_characters();
  Builder b(source);
  // Trailing blanks and line breaks are not part of the expression: an error at its end then
  // points just past its last character.
  const auto end = text.find_last_not_of(" \t\r\n");
  const std::size_t length = end == std::string_view::npos ? 0 : end + 1;
  run(b, whole_expression, text.data(), text.data() + length);
  return take_expr(b);
}

namespace {

std::string read_file(const std::string& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  // A device (/dev/zero never ends) or a FIFO (blocks without a writer) is no model file.
  if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) && !std::filesystem::is_directory(st))
    throw ParseError(path, 0, 0, "not a regular file (a device, a FIFO or a socket): only files are read", "");
  std::ifstream in;
  if (!std::filesystem::is_directory(st)) in.open(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, 0, "cannot open file", "");
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw ParseError(path, 0, 0, "cannot read file", "");
  return text;
}

}  // namespace

ModelFile read_model_file(const std::string& path) { return parse_model_file(read_file(path), path); }

ParFile read_par_file(const std::string& path) { return parse_par_file(read_file(path), path); }

}  // namespace symoro::grammar
