// readTissue, the one entry point for tissue files (io/TissueFiles.h): the reader is chosen by
// extension, case-insensitively, and an unknown extension is refused naming the file and what
// is read.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "io/Paths.h"
#include "io/TissueFiles.h"

using namespace tp;
using ::testing::HasSubstr;

TEST(TissueFiles, ReadsByExtensionWhateverItsCase) {
  const CellComplex a = readTissue(defaultTissuePath());
  const CellComplex b = readPly(defaultTissuePath());
  EXPECT_EQ(a.vertexCount(), b.vertexCount());
  EXPECT_EQ(a.triangleCount(), b.triangleCount());
  EXPECT_EQ(a.cellCount(), b.cellCount());
  const std::string upper = ::testing::TempDir() + "tp_tissue_upper.PLY";
  writePly(upper, b);
  TissueReadInfo info;
  const CellComplex c = readTissue(upper, &info);
  EXPECT_EQ(c.cellCount(), b.cellCount());
  EXPECT_FALSE(info.format.empty());
  std::remove(upper.c_str());
}

TEST(TissueFiles, UnknownExtensionIsRefusedNamingTheFileAndTheFormats) {
  const std::string path = ::testing::TempDir() + "tp_tissue.obj";
  std::ofstream(path) << "v 0 0 0\n";
  try {
    readTissue(path);
    FAIL() << "an .obj file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("'obj'"));
    EXPECT_THAT(e.what(), HasSubstr(".ply"));
  }
  std::remove(path.c_str());
  EXPECT_EQ(tissueFileFilter(), "Tissues (*.ply)");
}
