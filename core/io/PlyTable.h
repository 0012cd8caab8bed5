#pragma once
// A generic reader of PLY tables (Turk's format, as documented by Bourke: a header declaring
// elements and their typed properties, then the instances of each element in order, ASCII or
// binary of either endianness). It checks every value it is asked for against its declared type
// and locates every error (line in ASCII, element and index in binary), but knows nothing of
// tissues: io/Ply.cpp gives vertices, faces and volumes their meaning. Counts in the header are
// never trusted for allocation.

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace tp {

class PlyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace ply {

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

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  int line = 0;  // header line of the element
  bool allKnown() const;
  /// Index of the property called `name`, or -1.
  int find(std::string_view name) const;
};

enum class Format { Ascii, BinaryLittle, BinaryBig };

/// One instance of an element, as read: the properties asked for, by property index.
struct Instance {
  std::vector<double> values;              // scalars (0 where not asked for)
  std::vector<std::vector<double>> lists;  // lists (empty where not asked for)
};

/// Reads one PLY file held in memory. Elements are read (or skipped) in file order.
class TableReader {
 public:
  /// Parses the header; `name` starts every error message. Throws PlyError.
  TableReader(std::string data, std::string name);

  Format format() const { return format_; }
  const std::string& formatName() const { return formatName_; }
  const std::vector<Element>& elements() const { return elements_; }
  /// Index of the element called `name`, or -1.
  int findElement(std::string_view name) const;

  /// Throws unless the properties of element `e` marked in `wanted` can be read: in binary every
  /// property must have a PLY type (else nothing can be located); in ASCII, a value after one of
  /// unknown type cannot be located.
  void checkReadable(int e, const std::vector<char>& wanted) const;
  /// Whether element `e` can be read past (binary: only when every type is known).
  bool skippable(int e) const;

  /// Reads element `e`, which must be the next one in the file, parsing and checking the
  /// properties marked in `wanted` and reading past the others (ignored ASCII values are not
  /// checked); calls `visit(index, instance)` for each instance. An ASCII instance is one line.
  void read(int e, const std::vector<char>& wanted,
            const std::function<void(std::uint64_t, const Instance&)>& visit);
  /// Reads past element `e`, which must be the next one in the file.
  void skip(int e);
  /// Bytes after the last element read (ASCII white space does not count).
  std::uint64_t trailingBytes() const;

  [[noreturn]] void fail(const std::string& msg) const;
  /// Fails naming the instance being read: "line L (face 3)" or "element 'face' index 3".
  [[noreturn]] void failAt(const std::string& msg) const;
  /// The line of the instance being read (ASCII), else 0.
  int line() const { return format_ == Format::Ascii ? line_ : 0; }

 private:
  void parseHeader();
  bool nextLine(std::string_view& out);
  std::string where() const;
  [[noreturn]] void failTruncated() const;
  void enter(int e);
  void beginInstance();
  void endInstance(bool wholeLine);
  const char* take(std::size_t n);
  double decode(Scalar t, const char* p) const;
  double value(const Property& p, Scalar t, bool needed);
  std::uint64_t listCount(const Property& p);
  void skipList(const Property& p, std::uint64_t n);

  std::string data_, name_, formatName_;
  std::size_t pos_ = 0;
  int line_ = 0;
  Format format_ = Format::Ascii;
  bool swap_ = false;
  std::vector<Element> elements_;
  int next_ = 0;                   // next element in file order
  const Element* elem_ = nullptr;  // element being read, for messages
  std::uint64_t index_ = 0;        // its instance being read
  std::vector<std::string_view> tokens_;
  std::size_t token_ = 0;
};

// Helpers shared with the tissue interpretation.
/// A piece of file content for a message: at most 40 characters, control bytes escaped.
std::string excerpt(std::string_view s);
/// Shortest text that reads back as the same double.
std::string numberText(double v);

}  // namespace ply
}  // namespace tp
