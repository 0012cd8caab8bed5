#include "io/PlyTable.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace tp::ply {

namespace {

Scalar scalarFromName(std::string_view s) {
  if (s == "char" || s == "int8") return Scalar::Int8;
  if (s == "uchar" || s == "uint8") return Scalar::UInt8;
  if (s == "short" || s == "int16") return Scalar::Int16;
  if (s == "ushort" || s == "uint16") return Scalar::UInt16;
  if (s == "int" || s == "int32") return Scalar::Int32;
  if (s == "uint" || s == "uint32") return Scalar::UInt32;
  if (s == "float" || s == "float32") return Scalar::Float32;
  if (s == "double" || s == "float64") return Scalar::Float64;
  return Scalar::Unknown;
}

std::size_t scalarSize(Scalar t) {
  switch (t) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    case Scalar::Float64:
      return 8;
    case Scalar::Unknown:
      break;
  }
  return 0;
}

bool isInteger(Scalar t) {
  return t != Scalar::Float32 && t != Scalar::Float64 && t != Scalar::Unknown;
}

std::pair<long long, long long> integerRange(Scalar t) {
  switch (t) {
    case Scalar::Int8:
      return {-128, 127};
    case Scalar::UInt8:
      return {0, 255};
    case Scalar::Int16:
      return {-32768, 32767};
    case Scalar::UInt16:
      return {0, 65535};
    case Scalar::Int32:
      return {-2147483648LL, 2147483647LL};
    case Scalar::UInt32:
      return {0, 4294967295LL};
    default:
      break;
  }
  return {0, 0};
}

bool isBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

void splitWords(std::string_view line, std::vector<std::string_view>& words) {
  words.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isBlank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !isBlank(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && isBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && isBlank(s.back())) s.remove_suffix(1);
  return s;
}

// from_chars rejects a leading '+', which some writers emit.
std::string_view withoutPlus(std::string_view s) {
  return s.size() > 1 && s[0] == '+' && s[1] != '-' ? s.substr(1) : s;
}

bool parseInteger(std::string_view s, long long& v) {
  s = withoutPlus(s);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && end == s.data() + s.size();
}

bool parseReal(std::string_view s, double& v) {
  s = withoutPlus(s);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && end == s.data() + s.size();
}

template <class Int>
std::string str(Int v) {
  return std::to_string(v);
}

std::string str(double v) {  // shortest form that reads back exactly
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace

// A piece of file content for a message: at most 40 characters, control bytes escaped, because
// the "text" may be binary garbage.
std::string excerpt(std::string_view s) {
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 32 || c >= 127) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (s.size() > 40) out += "...";
  return out + "'";
}

std::string numberText(double v) {
  return str(v);
}

bool Element::allKnown() const {
  return std::all_of(properties.begin(), properties.end(),
                     [](const Property& p) { return p.knownType(); });
}

int Element::find(std::string_view name) const {
  for (int k = 0; k < static_cast<int>(properties.size()); ++k)
    if (properties[k].name == name) return k;
  return -1;
}

// ---------------------------------------------------------------------------------------------
// Header

TableReader::TableReader(std::string data, std::string name)
    : data_(std::move(data)), name_(std::move(name)) {
  parseHeader();
}

int TableReader::findElement(std::string_view name) const {
  for (int i = 0; i < static_cast<int>(elements_.size()); ++i)
    if (elements_[i].name == name) return i;
  return -1;
}

void TableReader::fail(const std::string& msg) const {
  throw PlyError(name_ + ": " + msg);
}

void TableReader::failAt(const std::string& msg) const {
  fail(where() + ": " + msg);
}

// Location of the current element instance: the line (ASCII) or element and index (binary).
std::string TableReader::where() const {
  const std::string what = elem_ ? elem_->name + " " + str(index_) : "data";
  if (format_ == Format::Ascii) return "line " + str(line_) + " (" + what + ")";
  return elem_ ? "element '" + elem_->name + "' index " + str(index_) : "data";
}

// Next line of the file without its end-of-line characters; false at the end of the data.
bool TableReader::nextLine(std::string_view& out) {
  if (pos_ >= data_.size()) return false;
  std::size_t end = data_.find('\n', pos_);
  if (end == std::string::npos) end = data_.size();
  out = std::string_view(data_).substr(pos_, end - pos_);
  if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
  pos_ = std::min(end + 1, data_.size());
  ++line_;
  return true;
}

void TableReader::parseHeader() {
  if (data_.empty()) fail("empty file (not a PLY file)");
  std::string_view line;
  nextLine(line);
  if (trim(line) != "ply")
    fail("not a PLY file: the first line is " + excerpt(line) + ", expected 'ply'");
  bool haveFormat = false, ended = false;
  std::vector<std::string_view> w;
  while (!ended && nextLine(line)) {
    splitWords(line, w);
    const std::string at = "line " + str(line_) + ": ";
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (w.size() < 2) fail(at + "'format' without a format name");
      if (w[1] == "ascii")
        format_ = Format::Ascii;
      else if (w[1] == "binary_little_endian")
        format_ = Format::BinaryLittle;
      else if (w[1] == "binary_big_endian")
        format_ = Format::BinaryBig;
      else
        fail(at + "unsupported format " + excerpt(w[1]) +
             " (expected ascii, binary_little_endian or binary_big_endian)");
      formatName_ = std::string(w[1]);
      haveFormat = true;
    } else if (w[0] == "element") {
      long long count = 0;
      if (w.size() != 3) fail(at + "expected 'element NAME COUNT', found " + excerpt(line));
      if (!parseInteger(w[2], count) || count < 0)
        fail(at + "element count " + excerpt(w[2]) + " is not a non-negative integer");
      for (const Element& e : elements_)
        if (e.name == w[1]) fail(at + "element '" + e.name + "' is declared twice");
      elements_.push_back(Element{std::string(w[1]), static_cast<std::uint64_t>(count), {}, line_});
    } else if (w[0] == "property") {
      if (elements_.empty()) fail(at + "'property' before any 'element'");
      Property p;
      p.line = line_;
      std::size_t nameWord = 2;
      if (w.size() >= 2 && w[1] == "list") {
        if (w.size() < 5) fail(at + "expected 'property list COUNT_TYPE ITEM_TYPE NAME'");
        p.isList = true;
        p.countType = scalarFromName(w[2]);
        p.type = scalarFromName(w[3]);
        p.typeText = "list " + std::string(w[2]) + " " + std::string(w[3]);
        if (p.countType == Scalar::Float32 || p.countType == Scalar::Float64)
          fail(at + "a list count type must be an integer type, not " + excerpt(w[2]));
        nameWord = 4;
      } else {
        if (w.size() < 3) fail(at + "expected 'property TYPE NAME'");
        p.type = scalarFromName(w[1]);
        p.typeText = std::string(w[1]);
      }
      // The name is the rest of the line: MorphoGraphX writes names with spaces.
      p.name = std::string(trim(line.substr(w[nameWord].data() - line.data())));
      elements_.back().properties.push_back(std::move(p));
    } else if (w[0] == "end_header") {
      ended = true;
    } else {
      fail(at + "unexpected header line " + excerpt(line));
    }
  }
  if (!ended) fail("the header has no 'end_header' line (truncated, or not a PLY file)");
  if (!haveFormat) fail("the header has no 'format' line");
  swap_ = format_ != Format::Ascii &&
          (format_ == Format::BinaryLittle) != (std::endian::native == std::endian::little);
}

void TableReader::checkReadable(int e, const std::vector<char>& wanted) const {
  const Element& el = elements_[e];
  int firstUnknown = -1;
  for (int k = 0; k < static_cast<int>(el.properties.size()); ++k) {
    const Property& p = el.properties[k];
    if (!p.knownType() && firstUnknown < 0) {
      firstUnknown = k;
      if (format_ != Format::Ascii)
        fail("property '" + p.name + "' of element '" + el.name + "' has type " +
             excerpt(p.typeText) + ", which is not a PLY type; a binary file cannot be read");
    }
    if (firstUnknown >= 0 && wanted[k])
      fail("property '" + p.name + "' of element '" + el.name + "' cannot be read: " +
           (k == firstUnknown
                ? "its type " + excerpt(p.typeText) + " is not a PLY type"
                : "it follows property '" + el.properties[firstUnknown].name +
                      "' of unknown type " + excerpt(el.properties[firstUnknown].typeText)));
  }
}

bool TableReader::skippable(int e) const {
  return format_ == Format::Ascii || elements_[e].allKnown();
}

// ---------------------------------------------------------------------------------------------
// Data

std::uint64_t TableReader::trailingBytes() const {
  if (pos_ >= data_.size()) return 0;
  if (format_ == Format::Ascii && data_.find_first_not_of(" \t\r\n\v\f", pos_) == std::string::npos)
    return 0;
  return data_.size() - pos_;
}

void TableReader::failTruncated() const {
  fail("premature end of file in element '" + elem_->name + "' at index " + str(index_) + " of " +
       str(elem_->count) + (format_ == Format::Ascii ? " (after line " + str(line_) + ")" : ""));
}

void TableReader::enter(int e) {
  if (e != next_)
    throw std::logic_error("PLY elements must be read in file order: element " + std::to_string(e) +
                           " asked for, " + std::to_string(next_) + " next");
  ++next_;
  elem_ = &elements_[e];
  index_ = 0;
}

// ASCII: the next non-blank line holds the current instance (one instance per line).
void TableReader::beginInstance() {
  if (format_ != Format::Ascii) return;
  std::string_view line;
  do {
    if (!nextLine(line)) failTruncated();
    splitWords(line, tokens_);
  } while (tokens_.empty());
  token_ = 0;
}

void TableReader::endInstance(bool wholeLine) {
  if (format_ == Format::Ascii && wholeLine && token_ < tokens_.size())
    failAt(str(static_cast<std::uint64_t>(tokens_.size() - token_)) +
           " value(s) more than element '" + elem_->name + "' declares");
}

const char* TableReader::take(std::size_t n) {
  if (data_.size() - pos_ < n) failTruncated();
  const char* p = data_.data() + pos_;
  pos_ += n;
  return p;
}

double TableReader::decode(Scalar t, const char* p) const {
  auto load = [&]<class T>(T) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, p, sizeof(T));
    if (swap_) std::reverse(bytes, bytes + sizeof(T));
    T v;
    std::memcpy(&v, bytes, sizeof(T));
    return static_cast<double>(v);
  };
  switch (t) {
    case Scalar::Int8:
      return load(std::int8_t{});
    case Scalar::UInt8:
      return load(std::uint8_t{});
    case Scalar::Int16:
      return load(std::int16_t{});
    case Scalar::UInt16:
      return load(std::uint16_t{});
    case Scalar::Int32:
      return load(std::int32_t{});
    case Scalar::UInt32:
      return load(std::uint32_t{});
    case Scalar::Float32:
      return load(float{});
    case Scalar::Float64:
      return load(double{});
    case Scalar::Unknown:
      break;
  }
  return 0;
}

// One value of type t; parsed only when `needed`.
double TableReader::value(const Property& p, Scalar t, bool needed) {
  if (format_ != Format::Ascii) {
    const char* b = take(scalarSize(t));
    return needed ? decode(t, b) : 0.0;
  }
  if (token_ >= tokens_.size())
    failAt("too few values: property '" + p.name + "' of element '" + elem_->name + "' is missing");
  const std::string_view tok = tokens_[token_++];
  if (!needed) return 0.0;
  if (isInteger(t)) {
    long long v = 0;
    if (!parseInteger(tok, v))
      failAt(excerpt(tok) + " is not an integer (property '" + p.name + "' of element '" +
             elem_->name + "')");
    const auto [lo, hi] = integerRange(t);
    if (v < lo || v > hi)
      failAt("value " + str(v) + " does not fit the type of property '" + p.name + "'");
    return static_cast<double>(v);
  }
  double v = 0;
  if (!parseReal(tok, v))
    failAt(excerpt(tok) + " is not a number (property '" + p.name + "' of element '" + elem_->name +
           "')");
  return v;
}

std::uint64_t TableReader::listCount(const Property& p) {
  const double n = value(p, p.countType, true);
  if (n < 0) failAt("negative list length " + str(n) + " for property '" + p.name + "'");
  return static_cast<std::uint64_t>(n);
}

// Checks that n items are there before anything is read or allocated; in binary, reads past them.
void TableReader::skipList(const Property& p, std::uint64_t n) {
  if (format_ != Format::Ascii) {
    const std::uint64_t size = scalarSize(p.type);
    if (n > (data_.size() - pos_) / size) failTruncated();
    pos_ += n * size;
    return;
  }
  if (n > tokens_.size() - token_)
    failAt("list '" + p.name + "' declares " + str(n) + " items but the line has only " +
           str(static_cast<std::uint64_t>(tokens_.size() - token_)) + " more value(s)");
  token_ += n;
}

void TableReader::read(int e, const std::vector<char>& wanted,
                       const std::function<void(std::uint64_t, const Instance&)>& visit) {
  enter(e);
  const Element& el = *elem_;
  checkReadable(e, wanted);
  Instance in;
  in.values.assign(el.properties.size(), 0.0);
  in.lists.resize(el.properties.size());
  for (index_ = 0; index_ < el.count; ++index_) {
    beginInstance();
    bool wholeLine = true;
    for (std::size_t k = 0; k < el.properties.size(); ++k) {
      const Property& p = el.properties[k];
      if (!p.knownType()) {  // ASCII only, and nothing wanted follows (checkReadable)
        wholeLine = false;
        break;
      }
      if (!p.isList) {
        in.values[k] = value(p, p.type, wanted[k]);
        continue;
      }
      const std::uint64_t n = listCount(p);
      if (!wanted[k]) {
        skipList(p, n);
        continue;
      }
      // The items must be there before they are stored (a huge count allocates nothing).
      const std::size_t start = pos_, token = token_;
      skipList(p, n);
      pos_ = start;
      token_ = token;
      std::vector<double>& list = in.lists[k];
      list.clear();
      for (std::uint64_t i = 0; i < n; ++i) list.push_back(value(p, p.type, true));
    }
    endInstance(wholeLine);
    visit(index_, in);
  }
  elem_ = nullptr;
}

void TableReader::skip(int e) {
  enter(e);
  const Element& el = *elem_;
  if (el.properties.empty()) {  // such instances occupy nothing
    elem_ = nullptr;
    return;
  }
  if (format_ == Format::Ascii) {
    // One instance per line; not tokenised, so values of unknown types do no harm.
    std::string_view line;
    for (index_ = 0; index_ < el.count; ++index_) {
      do {
        if (!nextLine(line)) failTruncated();
      } while (trim(line).empty());
    }
    elem_ = nullptr;
    return;
  }
  if (!el.allKnown())
    fail("element '" + el.name + "' has a property of unknown type, so a binary file cannot " +
         "be read past it");
  const bool fixedSize = std::none_of(el.properties.begin(), el.properties.end(),
                                      [](const Property& p) { return p.isList; });
  if (fixedSize) {  // one jump
    std::uint64_t size = 0;
    for (const Property& p : el.properties) size += scalarSize(p.type);
    const std::uint64_t fit = (data_.size() - pos_) / size;
    if (el.count > fit) {
      index_ = fit;
      failTruncated();
    }
    pos_ += el.count * size;
  } else {
    for (index_ = 0; index_ < el.count; ++index_)
      for (const Property& p : el.properties) {
        if (p.isList)
          skipList(p, listCount(p));
        else
          take(scalarSize(p.type));
      }
  }
  elem_ = nullptr;
}

}  // namespace tp::ply
