#include "io/CurveCsv.h"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "io/AtomicFile.h"

namespace tp {

namespace {

constexpr std::array<const char*, 5> kColumns = {"depth_um", "force_uN", "iterations", "residual",
                                                 "converged"};

void appendReal(std::string& out, double v) {
  if (std::isnan(v)) {  // one spelling, whatever the sign bit
    out += "nan";
    return;
  }
  char b[32];
  out.append(b, std::to_chars(b, b + sizeof b, v).ptr);  // shortest exact form; inf as "inf"
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(
        trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

std::string curveCsv(const std::vector<CurvePoint>& curve, const std::vector<std::string>& comments) {
  std::string s;
  for (const std::string& c : comments) {
    if (c.find('\n') != std::string::npos)
      throw std::invalid_argument("curveCsv: a comment line must not hold a line break");
    s += "# " + c + "\n";
  }
  s += "depth_um,force_uN,iterations,residual,converged\n";
  for (const CurvePoint& p : curve) {
    appendReal(s, p.depth);
    s += ',';
    appendReal(s, p.force);
    s += ',' + std::to_string(p.iterations) + ',';
    appendReal(s, p.residual);
    s += p.converged ? ",1\n" : ",0\n";
  }
  return s;
}

void writeCurveCsv(const std::string& path, const std::vector<CurvePoint>& curve,
                   const std::vector<std::string>& comments) {
  writeFileAtomically(path, std::string_view(curveCsv(curve, comments)));
}

std::vector<CurvePoint> parseCurveCsv(std::string_view text, const std::string& nameForErrors) {
  std::vector<CurvePoint> curve;
  std::vector<std::string> header;
  std::array<int, 5> column{};  // field index of each required column
  int unloadingColumn = -1;
  int lineNo = 0;
  std::size_t pos = 0;
  auto fail = [&](const std::string& m) {
    throw std::runtime_error(nameForErrors + ": line " + std::to_string(lineNo) + ": " + m);
  };
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = trim(text.substr(pos, end - pos));
    pos = end + 1;
    ++lineNo;
    if (line.empty() || line.front() == '#') continue;
    const auto fields = splitFields(line);
    if (header.empty()) {
      for (auto f : fields) header.emplace_back(f);
      for (std::size_t c = 0; c < kColumns.size(); ++c) {
        column[c] = -1;
        for (std::size_t i = 0; i < header.size(); ++i)
          if (header[i] == kColumns[c]) column[c] = static_cast<int>(i);
        if (column[c] < 0)
          fail("the header has no column '" + std::string(kColumns[c]) + "' (expected " +
               "depth_um,force_uN,iterations,residual,converged)");
      }
      for (std::size_t i = 0; i < header.size(); ++i)
        if (header[i] == "unloading") unloadingColumn = static_cast<int>(i);
      continue;
    }
    if (fields.size() != header.size())
      fail("expected " + std::to_string(header.size()) + " columns, found " +
           std::to_string(fields.size()));
    auto where = [&](int i) {
      return "column " + std::to_string(i + 1) + " (" + header[i] + "): '" +
             std::string(fields[i]) + "'";
    };
    auto real = [&](int i) {
      double v = 0;
      const std::string_view f = fields[i];
      const auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || ec != std::errc() || p != f.data() + f.size())
        fail(where(i) + " is not a number");
      return v;
    };
    auto integer = [&](int i) {
      int v = 0;
      const std::string_view f = fields[i];
      const auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || ec != std::errc() || p != f.data() + f.size())
        fail(where(i) + " is not an integer");
      return v;
    };
    auto flag = [&](int i) {
      if (fields[i] != "0" && fields[i] != "1") fail(where(i) + " is not 0 or 1");
      return fields[i] == "1";
    };
    CurvePoint p;
    p.depth = real(column[0]);
    p.force = real(column[1]);
    p.iterations = integer(column[2]);
    p.residual = real(column[3]);
    p.converged = flag(column[4]);
    if (unloadingColumn >= 0) p.unloading = flag(unloadingColumn);
    curve.push_back(p);
  }
  if (header.empty()) {
    lineNo = 1;
    fail("empty file: no header line");
  }
  return curve;
}

std::vector<CurvePoint> readCurveCsv(const std::string& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw std::runtime_error(
        path + ": cannot open: " + (err ? std::string(std::strerror(err)) : "unknown error"));
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path + ": read error");
  return parseCurveCsv(buffer.view(), path);
}

}  // namespace tp
