// libFuzzer target: the PLY reader (ASCII and binary, cell-complex properties) on arbitrary
// bytes. A reader may refuse its input only with std::runtime_error naming the problem; any
// other exception, a crash, a leak or undefined behaviour (ASan+UBSan build) is a finding.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "io/Ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    tp::PlyInfo info;
    const tp::CellComplex cc = tp::readPly(in, "fuzz.ply", &info);
    // What was accepted must be a usable complex: every index in range.
    for (const auto& t : cc.triangles)
      for (int v : t)
        if (v < 0 || v >= cc.vertexCount()) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
