#include "io/Ply.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <span>
#include <sstream>
#include <string_view>
#include <tuple>
#include <unordered_map>

namespace tp {

namespace {

// ---------------------------------------------------------------------------------------------
// Scalar types and number parsing

enum class Scalar : std::uint8_t {
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Float32,
  Float64,
  Unknown
};

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

// A piece of file content for a message: at most 40 characters, control bytes escaped, because
// the "text" may be binary garbage.
std::string quoted(std::string_view s) {
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

// ---------------------------------------------------------------------------------------------
// Header

struct Property {
  std::string name;
  bool isList = false;
  Scalar type = Scalar::Unknown;       // the scalar type, or a list's item type
  Scalar countType = Scalar::Unknown;  // lists only
  std::string typeText;                // as written, for messages about unknown types
  int line = 0;                        // header line
  bool knownType() const {
    return type != Scalar::Unknown && (!isList || countType != Scalar::Unknown);
  }
};

// What the reader does with a property.
enum class Role : std::uint8_t { Ignore, X, Y, Z, Fixed, Indices, Cell, Neighbor, Wall, Count };

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::vector<Role> roles;  // one per property
  int line = 0;             // header line of the element
  bool allKnown() const {
    return std::all_of(properties.begin(), properties.end(),
                       [](const Property& p) { return p.knownType(); });
  }
};

enum class Format { Ascii, BinaryLittle, BinaryBig };

// Semantic data read from the file, before it becomes a CellComplex.
struct RawFaces {
  std::vector<int> verts;                       // all polygons, concatenated
  std::vector<std::size_t> start{0};            // F + 1 offsets into verts
  std::vector<int> cell, neighbor, wall, line;  // per face (labels as in the file, -1 = none)
  int count() const { return static_cast<int>(cell.size()); }
  std::span<int> of(int f) { return {verts.data() + start[f], start[f + 1] - start[f]}; }
};

class PlyReader {
 public:
  PlyReader(std::string data, std::string name) : data_(std::move(data)), name_(std::move(name)) {}

  CellComplex read(PlyInfo& info) {
    parseHeader(info);
    assignRoles(info);
    readData(info);
    return assemble(info);
  }

 private:
  [[noreturn]] void fail(const std::string& msg) const { throw PlyError(name_ + ": " + msg); }
  [[noreturn]] void failAt(const std::string& msg) const { fail(where() + ": " + msg); }

  // Location of the current element instance: the line (ASCII) or element and index (binary).
  std::string where() const {
    const std::string what = elem_ ? elem_->name + " " + str(index_) : "data";
    if (format_ == Format::Ascii) return "line " + str(line_) + " (" + what + ")";
    return elem_ ? "element '" + elem_->name + "' index " + str(index_) : "data";
  }

  std::string faceName(int f) const {
    if (format_ == Format::Ascii) return "face " + str(f) + " (line " + str(faces_.line[f]) + ")";
    return "face " + str(f);
  }

  // Next line of the file without its end-of-line characters; false at the end of the data.
  bool nextLine(std::string_view& out) {
    if (pos_ >= data_.size()) return false;
    std::size_t end = data_.find('\n', pos_);
    if (end == std::string::npos) end = data_.size();
    out = std::string_view(data_).substr(pos_, end - pos_);
    if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
    pos_ = std::min(end + 1, data_.size());
    ++line_;
    return true;
  }

  void parseHeader(PlyInfo& info) {
    if (data_.empty()) fail("empty file (not a PLY file)");
    std::string_view line;
    nextLine(line);
    if (trim(line) != "ply")
      fail("not a PLY file: the first line is " + quoted(line) + ", expected 'ply'");
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
          fail(at + "unsupported format " + quoted(w[1]) +
               " (expected ascii, binary_little_endian or binary_big_endian)");
        info.format = std::string(w[1]);
        haveFormat = true;
      } else if (w[0] == "element") {
        long long count = 0;
        if (w.size() != 3) fail(at + "expected 'element NAME COUNT', found " + quoted(line));
        if (!parseInteger(w[2], count) || count < 0)
          fail(at + "element count " + quoted(w[2]) + " is not a non-negative integer");
        for (const Element& e : elements_)
          if (e.name == w[1]) fail(at + "element '" + e.name + "' is declared twice");
        elements_.push_back(
            Element{std::string(w[1]), static_cast<std::uint64_t>(count), {}, {}, line_});
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
            fail(at + "a list count type must be an integer type, not " + quoted(w[2]));
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
        fail(at + "unexpected header line " + quoted(line));
      }
    }
    if (!ended) fail("the header has no 'end_header' line (truncated, or not a PLY file)");
    if (!haveFormat) fail("the header has no 'format' line");
    swap_ = format_ != Format::Ascii &&
            (format_ == Format::BinaryLittle) != (std::endian::native == std::endian::little);
  }

  void assignRoles(PlyInfo& info) {
    for (int i = 0; i < static_cast<int>(elements_.size()); ++i) {
      if (elements_[i].name == "vertex") vertexElement_ = i;
      if (elements_[i].name == "face") faceElement_ = i;
    }
    if (vertexElement_ < 0) fail("no 'vertex' element in the header");
    if (faceElement_ < 0 || elements_[faceElement_].count == 0) {
      std::string names;
      for (const Element& e : elements_) names += (names.empty() ? "" : ", ") + e.name;
      fail("no faces: a tissue needs an element 'face' with at least one face (this file has " +
           (names.empty() ? std::string("no elements") : "elements " + names) +
           "; a cell graph or point cloud is not a tissue)");
    }
    Element& ve = elements_[vertexElement_];
    Element& fe = elements_[faceElement_];
    if (ve.count > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      fail("element 'vertex' declares " + str(ve.count) + " vertices, more than supported");
    if (fe.count > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      fail("element 'face' declares " + str(fe.count) + " faces, more than supported");
    vertexCount_ = static_cast<int>(ve.count);

    auto find = [](const Element& e, const char* name) {
      for (int k = 0; k < static_cast<int>(e.properties.size()); ++k)
        if (e.properties[k].name == name) return k;
      return -1;
    };
    auto use = [&](Element& e, int k, Role r, bool list) {
      if (k < 0) return;
      const Property& p = e.properties[k];
      if (p.isList != list)
        fail("line " + str(p.line) + ": property '" + p.name + "' of element '" + e.name +
             "' must be " + (list ? "a list" : "a single value, not a list"));
      e.roles[k] = r;
    };
    ve.roles.assign(ve.properties.size(), Role::Ignore);
    fe.roles.assign(fe.properties.size(), Role::Ignore);
    for (const char* c : {"x", "y", "z"})
      if (find(ve, c) < 0) fail("element 'vertex' has no property '" + std::string(c) + "'");
    use(ve, find(ve, "x"), Role::X, false);
    use(ve, find(ve, "y"), Role::Y, false);
    use(ve, find(ve, "z"), Role::Z, false);
    use(ve, find(ve, "fixed"), Role::Fixed, false);

    int indices = find(fe, "vertex_indices");
    if (indices < 0) indices = find(fe, "vertex_index");
    if (indices < 0)
      fail("element 'face' has no list property 'vertex_indices' (or 'vertex_index')");
    use(fe, indices, Role::Indices, true);
    int cell = find(fe, "cell");
    info.cellProperty = "cell";
    if (cell < 0) {
      // MorphoGraphX: the face label is the cell. Only a single value can be one.
      cell = find(fe, "label");
      info.cellProperty = "label";
      if (cell >= 0 && fe.properties[cell].isList) cell = -1;
    }
    if (cell < 0) info.cellProperty.clear();
    labelled_ = cell >= 0;
    info.hadCellLabels = labelled_;
    use(fe, cell, Role::Cell, false);
    if (labelled_)
      use(fe, find(fe, "neighbor"), Role::Neighbor, false);
    else if (find(fe, "neighbor") >= 0)
      info.notes.push_back("faces have 'neighbor' but no cell labels: 'neighbor' ignored");
    use(fe, find(fe, "wall"), Role::Wall, false);
    if (!labelled_) findVolumes(info, find);
    for (Role r : fe.roles) {
      hasNeighbor_ = hasNeighbor_ || r == Role::Neighbor;
      hasWall_ = hasWall_ || r == Role::Wall;
    }

    for (Element* e : {&ve, &fe}) {
      // A value after one of unknown type cannot be located (binary: cannot even be skipped).
      int firstUnknown = -1;
      for (int k = 0; k < static_cast<int>(e->properties.size()); ++k) {
        const Property& p = e->properties[k];
        if (!p.knownType() && firstUnknown < 0) {
          firstUnknown = k;
          if (format_ != Format::Ascii)
            fail("property '" + p.name + "' of element '" + e->name + "' has type " +
                 quoted(p.typeText) + ", which is not a PLY type; a binary file cannot be read");
        }
        if (firstUnknown >= 0 && e->roles[k] != Role::Ignore)
          fail("property '" + p.name + "' of element '" + e->name + "' cannot be read: " +
               (k == firstUnknown
                    ? "its type " + quoted(p.typeText) + " is not a PLY type"
                    : "it follows property '" + e->properties[firstUnknown].name +
                          "' of unknown type " + quoted(e->properties[firstUnknown].typeText)));
      }
      for (std::size_t k = 0; k < e->properties.size(); ++k)
        if (e->roles[k] == Role::Ignore)
          info.ignoredProperties.push_back(e->name + "." + e->properties[k].name);
    }
    for (int i = 0; i < static_cast<int>(elements_.size()); ++i)
      if (i != vertexElement_ && i != faceElement_ && i != volumeElement_)
        info.ignoredElements.push_back(elements_[i].name);
  }

  // openalea (PropertyTopomesh PLY): an element `volume` per cell, a list `face_index` of its
  // faces and an integer `label`. Used for the cells when the faces carry no labels.
  template <class Find>
  void findVolumes(PlyInfo& info, Find&& find) {
    for (int i = 0; i < static_cast<int>(elements_.size()); ++i) {
      const Element& e = elements_[i];
      if (e.name != "volume") continue;
      int faces = find(e, "face_index");
      if (faces < 0) faces = find(e, "face_indices");
      const int label = find(e, "label");
      if (faces < 0 || label < 0 || !e.properties[faces].isList || e.properties[label].isList) {
        info.notes.push_back("element 'volume' has no list 'face_index' and integer 'label': "
                             "not used for cell labels");
        return;
      }
      // Every value up to the last one used must be readable (in binary, every value).
      const int last = format_ == Format::Ascii ? std::max(faces, label)
                                                : static_cast<int>(e.properties.size()) - 1;
      for (int k = 0; k <= last; ++k)
        if (!e.properties[k].knownType()) {
          info.notes.push_back("element 'volume': property '" + e.properties[k].name +
                               "' has type " + quoted(e.properties[k].typeText) +
                               ", not a PLY type, so the cells' faces cannot be read");
          return;
        }
      volumeElement_ = i;
      volumeFaces_ = faces;
      volumeLabel_ = label;
      labelled_ = true;
      info.hadCellLabels = true;
      info.cellProperty = "volume.label";
      return;
    }
  }

  // --- data -----------------------------------------------------------------------------------

  void readData(PlyInfo& info) {
    bool haveVertices = false, haveFaces = false;
    for (Element& e : elements_) {
      elem_ = &e;
      index_ = 0;
      const bool used = &e == &elements_[vertexElement_] || &e == &elements_[faceElement_] ||
                        (volumeElement_ >= 0 && &e == &elements_[volumeElement_]);
      if (!used && format_ != Format::Ascii && !e.allKnown()) {
        // Its instance size is unknown: nothing after it can be reached.
        if (haveVertices && haveFaces) {
          info.notes.push_back("stopped reading at element '" + e.name +
                               "' (a property of unknown type); it and later elements ignored");
          break;
        }
        fail("element '" + e.name + "' has a property of unknown type, so a binary file cannot " +
             "be read past it to the vertices or faces");
      }
      if (&e == &elements_[vertexElement_]) {
        readVertices(e);
        haveVertices = true;
      } else if (&e == &elements_[faceElement_]) {
        readFaces(e);
        haveFaces = true;
      } else if (volumeElement_ >= 0 && &e == &elements_[volumeElement_]) {
        readVolumes(e);
      } else {
        skipElement(e);
      }
    }
    elem_ = nullptr;
    if (volumeElement_ >= 0) applyVolumes(info);
    if (pos_ < data_.size()) {
      const bool onlySpace = format_ == Format::Ascii &&
                             data_.find_first_not_of(" \t\r\n\v\f", pos_) == std::string::npos;
      if (!onlySpace)
        info.notes.push_back(str(static_cast<std::uint64_t>(data_.size() - pos_)) +
                             " bytes after the last element ignored");
    }
  }

  [[noreturn]] void failTruncated() const {
    fail("premature end of file in element '" + elem_->name + "' at index " + str(index_) + " of " +
         str(elem_->count) + (format_ == Format::Ascii ? " (after line " + str(line_) + ")" : ""));
  }

  // ASCII: the next non-blank line holds the current instance (one instance per line).
  void beginInstance() {
    if (format_ != Format::Ascii) return;
    std::string_view line;
    do {
      if (!nextLine(line)) failTruncated();
      splitWords(line, tokens_);
    } while (tokens_.empty());
    token_ = 0;
  }

  void endInstance(bool wholeLine) {
    if (format_ == Format::Ascii && wholeLine && token_ < tokens_.size())
      failAt(str(static_cast<std::uint64_t>(tokens_.size() - token_)) +
             " value(s) more than element '" + elem_->name + "' declares");
  }

  const char* take(std::size_t n) {
    if (data_.size() - pos_ < n) failTruncated();
    const char* p = data_.data() + pos_;
    pos_ += n;
    return p;
  }

  template <class T>
  T load(const char* p) const {
    char bytes[sizeof(T)];
    std::memcpy(bytes, p, sizeof(T));
    if (swap_) std::reverse(bytes, bytes + sizeof(T));
    T v;
    std::memcpy(&v, bytes, sizeof(T));
    return v;
  }

  double decode(Scalar t, const char* p) const {
    switch (t) {
      case Scalar::Int8:
        return load<std::int8_t>(p);
      case Scalar::UInt8:
        return load<std::uint8_t>(p);
      case Scalar::Int16:
        return load<std::int16_t>(p);
      case Scalar::UInt16:
        return load<std::uint16_t>(p);
      case Scalar::Int32:
        return load<std::int32_t>(p);
      case Scalar::UInt32:
        return load<std::uint32_t>(p);
      case Scalar::Float32:
        return load<float>(p);
      case Scalar::Float64:
        return load<double>(p);
      case Scalar::Unknown:
        break;
    }
    return 0;
  }

  // One value of type t; parsed only when `needed` (ignored ASCII values are not checked).
  double value(const Property& p, Scalar t, bool needed) {
    if (format_ != Format::Ascii) {
      const char* b = take(scalarSize(t));
      return needed ? decode(t, b) : 0.0;
    }
    if (token_ >= tokens_.size())
      failAt("too few values: property '" + p.name + "' of element '" + elem_->name +
             "' is missing");
    const std::string_view tok = tokens_[token_++];
    if (!needed) return 0.0;
    if (isInteger(t)) {
      long long v = 0;
      if (!parseInteger(tok, v))
        failAt(quoted(tok) + " is not an integer (property '" + p.name + "' of element '" +
               elem_->name + "')");
      const auto [lo, hi] = integerRange(t);
      if (v < lo || v > hi)
        failAt("value " + str(v) + " does not fit the type of property '" + p.name + "'");
      return static_cast<double>(v);
    }
    double v = 0;
    if (!parseReal(tok, v))
      failAt(quoted(tok) + " is not a number (property '" + p.name + "' of element '" +
             elem_->name + "')");
    return v;
  }

  std::uint64_t listCount(const Property& p) {
    const double n = value(p, p.countType, true);
    if (n < 0) failAt("negative list length " + str(n) + " for property '" + p.name + "'");
    return static_cast<std::uint64_t>(n);
  }

  void skipList(const Property& p, std::uint64_t n) {
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

  int integral(double v, const char* what) const {
    if (!(v == std::floor(v)) || v < std::numeric_limits<int>::min() ||
        v > std::numeric_limits<int>::max())
      failAt(std::string(what) + " " + str(v) + " is not an integer in the range of int");
    return static_cast<int>(v);
  }

  // Reads one instance of a used element into `val` (by role) and `list` (the face's indices).
  void readInstance(const Element& e, double* val, std::vector<int>* list) {
    beginInstance();
    bool wholeLine = true;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      const Role r = e.roles[k];
      if (!p.knownType()) {  // ASCII only, and nothing used follows (checked in the header)
        wholeLine = false;
        break;
      }
      if (!p.isList) {
        val[static_cast<int>(r)] = value(p, p.type, r != Role::Ignore);
        continue;
      }
      const std::uint64_t n = listCount(p);
      if (r != Role::Indices) {
        skipList(p, n);
        continue;
      }
      if (n < 3) failAt("a face with " + str(n) + " vertices (at least 3 are needed)");
      if (n > static_cast<std::uint64_t>(vertexCount_))
        failAt("a face with " + str(n) + " vertices, but the file has only " + str(vertexCount_) +
               " vertices");
      list->clear();
      for (std::uint64_t i = 0; i < n; ++i) {
        const double v = value(p, p.type, true);
        if (!(v >= 0 && v < vertexCount_ && v == std::floor(v)))
          failAt("vertex index " + str(v) + " out of range (the file has " + str(vertexCount_) +
                 " vertices, 0.." + str(vertexCount_ - 1) + ")");
        list->push_back(static_cast<int>(v));
      }
    }
    endInstance(wholeLine);
  }

  void readVertices(const Element& e) {
    // Reserve only what the bytes left could hold (a vertex takes at least 3), not the count.
    const std::size_t n = std::min<std::uint64_t>(e.count, (data_.size() - pos_) / 3);
    xyz_.reserve(3 * n);
    fixed_.reserve(n);
    double val[static_cast<int>(Role::Count)] = {};
    for (index_ = 0; index_ < e.count; ++index_) {
      readInstance(e, val, nullptr);
      for (Role r : {Role::X, Role::Y, Role::Z}) {
        const double c = val[static_cast<int>(r)];
        if (!std::isfinite(c))
          failAt(std::string("coordinate ") + "xyz"[static_cast<int>(r) - 1] + " is " + str(c) +
                 " (not finite)");
        if (std::abs(c) > kMaxCoordinate)  // 1 m: beyond any tissue, and volumes would overflow
          failAt(std::string("coordinate ") + "xyz"[static_cast<int>(r) - 1] + " is " + str(c) +
                 " µm (at most " + str(kMaxCoordinate) + " µm in magnitude)");
        xyz_.push_back(c);
      }
      fixed_.push_back(val[static_cast<int>(Role::Fixed)] != 0 ? 1 : 0);
    }
  }

  void readFaces(const Element& e) {
    double val[static_cast<int>(Role::Count)] = {};
    std::vector<int> list;
    std::vector<int> sorted;
    for (index_ = 0; index_ < e.count; ++index_) {
      val[static_cast<int>(Role::Cell)] = val[static_cast<int>(Role::Neighbor)] = -1;
      val[static_cast<int>(Role::Wall)] = -1;
      readInstance(e, val, &list);
      sorted = list;
      std::sort(sorted.begin(), sorted.end());
      const auto rep = std::adjacent_find(sorted.begin(), sorted.end());
      if (rep != sorted.end()) failAt("the face repeats vertex " + str(*rep));
      faces_.verts.insert(faces_.verts.end(), list.begin(), list.end());
      faces_.start.push_back(faces_.verts.size());
      faces_.cell.push_back(integral(val[static_cast<int>(Role::Cell)], "cell label"));
      faces_.neighbor.push_back(integral(val[static_cast<int>(Role::Neighbor)], "neighbor label"));
      faces_.wall.push_back(integral(val[static_cast<int>(Role::Wall)], "wall id"));
      faces_.line.push_back(format_ == Format::Ascii ? line_ : 0);
    }
  }

  // One cell per instance: its label and the indices of its faces.
  void readVolumes(const Element& e) {
    const std::uint64_t faceCount = elements_[faceElement_].count;
    for (index_ = 0; index_ < e.count; ++index_) {
      beginInstance();
      Volume v;
      v.where = where();
      bool wholeLine = true;
      for (int k = 0; k < static_cast<int>(e.properties.size()); ++k) {
        const Property& p = e.properties[k];
        if (!p.knownType()) {  // ASCII only, after the used properties (checked in the header)
          wholeLine = false;
          break;
        }
        if (k == volumeLabel_) {
          v.label = integral(value(p, p.type, true), "cell label");
          if (v.label < 0) failAt("cell label " + str(v.label) + " is negative");
        } else if (k == volumeFaces_) {
          const std::uint64_t n = listCount(p);
          if (n > faceCount)
            failAt("a cell with " + str(n) + " faces, but the file has only " + str(faceCount));
          for (std::uint64_t j = 0; j < n; ++j) {
            const double f = value(p, p.type, true);
            if (!(f >= 0 && f < static_cast<double>(faceCount) && f == std::floor(f)))
              failAt("face index " + str(f) + " out of range (the file has " + str(faceCount) +
                     " faces)");
            v.faces.push_back(static_cast<int>(f));
          }
        } else if (p.isList) {
          skipList(p, listCount(p));
        } else {
          value(p, p.type, false);
        }
      }
      endInstance(wholeLine);
      volumes_.push_back(std::move(v));
    }
  }

  // A face listed by one volume has it as its cell, by two: cell and neighbour (the face's
  // winding then says nothing of which is which; the first volume is taken as the cell).
  void applyVolumes(PlyInfo& info) {
    int empty = 0;
    for (const Volume& v : volumes_) {
      if (v.faces.empty()) ++empty;
      for (int f : v.faces) {
        int& c = faces_.cell[f];
        int& n = faces_.neighbor[f];
        if (c == v.label || n == v.label) continue;
        if (c < 0) {
          c = v.label;
        } else if (n < 0) {
          n = v.label;
          hasNeighbor_ = true;
        } else {
          fail(v.where + ": face " + str(f) + " is already a wall of cells " + str(c) + " and " +
               str(n) + "; it cannot also bound cell " + str(v.label));
        }
      }
    }
    if (empty)
      info.notes.push_back(str(empty) + " volume(s) with no faces (cells without a wall) ignored");
  }

  void skipElement(const Element& e) {
    if (e.properties.empty()) return;  // such instances occupy nothing
    if (format_ == Format::Ascii) {
      // One instance per line; not tokenised, so values of unknown types do no harm.
      std::string_view line;
      for (index_ = 0; index_ < e.count; ++index_) {
        do {
          if (!nextLine(line)) failTruncated();
        } while (trim(line).empty());
      }
      return;
    }
    const bool fixedSize = std::none_of(e.properties.begin(), e.properties.end(),
                                        [](const Property& p) { return p.isList; });
    if (fixedSize) {  // one jump
      std::uint64_t size = 0;
      for (const Property& p : e.properties) size += scalarSize(p.type);
      const std::uint64_t fit = (data_.size() - pos_) / size;
      if (e.count > fit) {
        index_ = fit;
        failTruncated();
      }
      pos_ += e.count * size;
      return;
    }
    for (index_ = 0; index_ < e.count; ++index_)
      for (const Property& p : e.properties) {
        if (p.isList)
          skipList(p, listCount(p));
        else
          take(scalarSize(p.type));
      }
  }

  // --- assembly -------------------------------------------------------------------------------

  CellComplex assemble(PlyInfo& info);
  void resolveLabels(std::vector<char>& keep, PlyInfo& info);
  bool closedSurface();
  void checkConsistentWinding();

  std::string data_, name_;
  std::size_t pos_ = 0;
  int line_ = 0;
  Format format_ = Format::Ascii;
  bool swap_ = false;
  std::vector<Element> elements_;
  int vertexElement_ = -1, faceElement_ = -1, vertexCount_ = 0;
  int volumeElement_ = -1, volumeFaces_ = -1, volumeLabel_ = -1;  // openalea cells
  struct Volume {
    int label = -1;
    std::vector<int> faces;
    std::string where;  // for messages
  };
  std::vector<Volume> volumes_;
  bool labelled_ = false, hasNeighbor_ = false, hasWall_ = false;
  const Element* elem_ = nullptr;  // element being read, for messages
  std::uint64_t index_ = 0;        // its instance being read
  std::vector<std::string_view> tokens_;
  std::size_t token_ = 0;
  std::vector<double> xyz_;
  std::vector<std::uint8_t> fixed_;
  RawFaces faces_;
};

enum class Winding { Same, Reversed, Other };

// How two faces over the same vertex set are wound relative to each other.
Winding compareWinding(std::span<const int> a, std::span<const int> b) {
  const std::size_t n = a.size();
  if (b.size() != n) return Winding::Other;
  const std::size_t p = static_cast<std::size_t>(std::find(b.begin(), b.end(), a[0]) - b.begin());
  if (p == n) return Winding::Other;
  bool same = true, reversed = true;
  for (std::size_t k = 0; k < n; ++k) {
    same = same && a[k] == b[(p + k) % n];
    reversed = reversed && a[k] == b[(p + n - k) % n];
  }
  return same ? Winding::Same : reversed ? Winding::Reversed : Winding::Other;
}

struct VectorHash {
  std::size_t operator()(const std::vector<int>& v) const {
    std::size_t h = v.size();
    for (int x : v) h = h * 1000003u ^ static_cast<std::size_t>(static_cast<unsigned>(x));
    return h;
  }
};

std::string cellsText(int cell, int neighbor) {
  return "cell " + str(cell) + ", neighbor " + str(neighbor);
}

// Normalises labels, and drops the second copy of every wall written from both sides.
void PlyReader::resolveLabels(std::vector<char>& keep, PlyInfo& info) {
  const int F = faces_.count();
  int turned = 0, twins = 0, duplicates = 0;
  for (int f = 0; f < F; ++f) {
    int& c = faces_.cell[f];
    int& n = faces_.neighbor[f];
    c = std::max(c, -1);
    n = std::max(n, -1);
    if (c >= 0 && c == n) fail(faceName(f) + ": cell and neighbor are both " + str(c));
    if (c < 0 && n >= 0) {  // only the cell on the far side: turn the face round
      const auto v = faces_.of(f);
      std::reverse(v.begin(), v.end());
      std::swap(c, n);
      ++turned;
    }
  }
  std::unordered_map<std::vector<int>, int, VectorHash> firstWithSet;
  firstWithSet.reserve(F);
  for (int f = 0; f < F; ++f) {
    const auto vf = faces_.of(f);
    std::vector<int> key(vf.begin(), vf.end());
    std::sort(key.begin(), key.end());
    const auto [it, inserted] = firstWithSet.try_emplace(std::move(key), f);
    if (inserted) continue;
    const int g = it->second;
    const int cf = faces_.cell[f], nf = faces_.neighbor[f];
    int& cg = faces_.cell[g];
    int& ng = faces_.neighbor[g];
    const std::string both = faceName(f) + " (" + cellsText(cf, nf) + ") and " + faceName(g) +
                             " (" + cellsText(cg, ng) + ")";
    switch (compareWinding(faces_.of(g), vf)) {
      case Winding::Other:
        fail(both + " have the same vertices in a different order");
      case Winding::Same:
        // (Without a `neighbor` property, g's neighbor may come from its twin.)
        if (cf != cg || (hasNeighbor_ && nf != ng))
          fail(both + " are the same face with different cells");
        ++duplicates;
        break;
      case Winding::Reversed:
        // The same wall seen from its other side.
        if (hasNeighbor_) {
          if (cf != ng || nf != cg) fail(both + " are one wall seen from both sides but disagree");
        } else {
          if (cf < 0 || cg < 0 || (ng >= 0 && ng != cf))
            fail(both + " are one wall seen from both sides but disagree");
          ng = cf;
        }
        ++twins;
        break;
    }
    keep[f] = 0;
  }
  if (turned) info.notes.push_back(str(turned) + " face(s) with only a neighbor turned round");
  if (twins) info.notes.push_back(str(twins) + " wall face(s) given from both sides merged");
  if (duplicates) info.notes.push_back(str(duplicates) + " duplicate face(s) dropped");
}

// True when the faces form a closed surface: every directed edge exactly once, with its reverse.
bool PlyReader::closedSurface() {
  std::vector<std::uint64_t> edges;
  edges.reserve(faces_.verts.size());
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
  };
  for (int f = 0; f < faces_.count(); ++f) {
    const auto v = faces_.of(f);
    for (std::size_t k = 0; k < v.size(); ++k) edges.push_back(key(v[k], v[(k + 1) % v.size()]));
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  for (std::uint64_t e : edges)
    if (!std::binary_search(edges.begin(), edges.end(), (e << 32) | (e >> 32))) return false;
  return true;
}

// An unlabelled surface that is closed but for the winding of some faces (every edge shared by
// exactly two faces, some pairs running it the same way) is refused with the faces named: read
// as a sheet it would silently lose its cell and its pressure.
void PlyReader::checkConsistentWinding() {
  struct Use {
    int a, b, face;
  };
  std::vector<Use> uses;
  for (int f = 0; f < faces_.count(); ++f) {
    const auto v = faces_.of(f);
    for (std::size_t k = 0; k < v.size(); ++k) {
      const int a = v[k], b = v[(k + 1) % v.size()];
      uses.push_back({std::min(a, b), std::max(a, b), f});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const Use& x, const Use& y) {
    return std::tie(x.a, x.b, x.face) < std::tie(y.a, y.b, y.face);
  });
  std::vector<std::pair<int, int>> flipped;  // pairs of faces running an edge the same way
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].a == uses[i].a && uses[j].b == uses[i].b) ++j;
    if (j - i != 2) return;  // an open or non-manifold surface: a sheet, as documented
    auto runsForward = [&](const Use& u) {
      const auto v = faces_.of(u.face);
      for (std::size_t k = 0; k < v.size(); ++k)
        if (v[k] == u.a && v[(k + 1) % v.size()] == u.b) return true;
      return false;
    };
    if (runsForward(uses[i]) == runsForward(uses[i + 1]))
      flipped.emplace_back(uses[i].face, uses[i + 1].face);
    i = j;
  }
  if (flipped.empty()) return;
  std::string list;
  for (std::size_t k = 0; k < std::min<std::size_t>(flipped.size(), 5); ++k)
    list += (k ? ", " : "") + std::to_string(flipped[k].first) + " and " +
            std::to_string(flipped[k].second);
  fail("the surface is closed but its faces are not wound consistently: " +
       std::to_string(flipped.size()) + " edge(s) run the same way in both of their faces (faces " +
       list + (flipped.size() > 5 ? ", …" : "") +
       "); wind every face the same way round (e.g. outward)");
}

CellComplex PlyReader::assemble(PlyInfo& info) {
  CellComplex cc;
  const int V = vertexCount_, F = faces_.count();
  cc.rest = Eigen::Map<const Points>(xyz_.data(), 3, V);
  cc.fixed = std::move(fixed_);
  std::vector<char> keep(F, 1);
  std::vector<int> labels;
  bool closed = false;
  if (labelled_) {
    resolveLabels(keep, info);
    for (int f = 0; f < F; ++f)
      if (keep[f])
        for (int c : {faces_.cell[f], faces_.neighbor[f]})
          if (c >= 0) labels.push_back(c);
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  } else if (closedSurface()) {
    closed = true;
    labels = {0};
    std::fill(faces_.cell.begin(), faces_.cell.end(), 0);
    std::fill(faces_.neighbor.begin(), faces_.neighbor.end(), -1);
  } else {
    checkConsistentWinding();
    std::fill(faces_.cell.begin(), faces_.cell.end(), -1);
    std::fill(faces_.neighbor.begin(), faces_.neighbor.end(), -1);
  }
  auto dense = [&](int label) {
    if (label < 0) return -1;
    return static_cast<int>(std::lower_bound(labels.begin(), labels.end(), label) - labels.begin());
  };

  std::unordered_map<int, int> wallOfId;           // file wall id -> wall
  std::map<std::pair<int, int>, int> wallOfCells;  // (cell, neighbor) -> wall of loose triangles
  std::vector<int> firstFace;                      // first face of each wall, for messages
  for (int f = 0; f < F; ++f) {
    if (!keep[f]) continue;
    const auto v = faces_.of(f);
    const int cell = dense(faces_.cell[f]), neighbor = dense(faces_.neighbor[f]);
    const int newWall = cc.wallCount();
    int w = newWall;
    if (hasWall_ && faces_.wall[f] >= 0) {
      w = wallOfId.try_emplace(faces_.wall[f], newWall).first->second;
      if (w != newWall) {
        Wall& wall = cc.walls[w];
        if (wall.cell != cell || wall.neighbor != neighbor)
          fail(faceName(f) + " is in wall " + str(faces_.wall[f]) + " with " +
               faceName(firstFace[w]) + " but bounds other cells (" +
               cellsText(faces_.cell[f], faces_.neighbor[f]) + " instead of " +
               cellsText(faces_.cell[firstFace[w]], faces_.neighbor[firstFace[w]]) + ")");
        wall.polygon.clear();  // several faces: no single boundary loop
      }
    } else if (v.size() == 3) {
      w = wallOfCells.try_emplace({cell, neighbor}, newWall).first->second;
    }
    if (w == newWall) {
      Wall wall;
      wall.cell = cell;
      wall.neighbor = neighbor;
      if (v.size() > 3) wall.polygon.assign(v.begin(), v.end());
      cc.walls.push_back(std::move(wall));
      firstFace.push_back(f);
    }
    if (v.size() == 3) {
      cc.triangles.emplace_back(v[0], v[1], v[2]);
      cc.triangleWall.push_back(w);
      continue;
    }
    for (const auto& t : triangulatePolygon(cc.rest, std::vector<int>(v.begin(), v.end()))) {
      cc.triangles.push_back(t);
      cc.triangleWall.push_back(w);
    }
  }
  cc.cellLabels = std::move(labels);
  if (closed && cellVolumes(cc, cc.rest)[0] < 0) {
    for (auto& t : cc.triangles) std::swap(t[1], t[2]);
    for (Wall& w : cc.walls) std::reverse(w.polygon.begin(), w.polygon.end());
    info.notes.push_back("closed surface wound inward: winding reversed");
  }
  if (!labelled_)
    info.notes.push_back(closed ? "no cell labels: a closed surface, read as one cell (label 0)"
                                : "no cell labels: an open surface, read as a sheet (no cell)");
  return cc;
}

}  // namespace

CellComplex readPly(std::istream& in, const std::string& nameForErrors, PlyInfo* info) {
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw PlyError(nameForErrors + ": read error");
  PlyInfo local;
  PlyInfo& out = info ? *info : local;
  out = PlyInfo{};
  PlyReader reader(std::move(buffer).str(), nameForErrors);
  return reader.read(out);
}

CellComplex readPly(const std::string& path, PlyInfo* info) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw PlyError(path + ": cannot open: " +
                   (err ? std::string(std::strerror(err)) : std::string("unknown error")));
  }
  return readPly(in, path, info);
}

}  // namespace tp
