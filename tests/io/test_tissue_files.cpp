// readTissue, the one entry point for tissue files (io/TissueFiles.h): the reader is chosen by
// extension, case-insensitively, and an unknown extension is refused naming the file and what
// is read. readSimulationTissue adds the checks every simulation makes (CLI, application, maps).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "io/Paths.h"
#include "io/TissueFiles.h"
#include "support/SharedData.h"

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

TEST(TissueFiles, SimulationTissueRefusesASurfaceMeshAndAnUnclampedTissueSayingWhy) {
  // The shipped tissue passes, with the cells and walls readTissue gives.
  const CellComplex ok = readSimulationTissue(defaultTissuePath());
  EXPECT_EQ(ok.cellCount(), readTissue(defaultTissuePath()).cellCount());

  // A MorphoGraphX surface mesh (outer walls only, every cell open): named as such, with the way out.
  const std::string surface =
      tp::test::sharedDataFile("mgx2r_meristem_morphographx/mesh_meristem_full_T0.ply");
  TP_SKIP_WITHOUT_DATA(surface);
  try {
    readSimulationTissue(surface);
    FAIL() << "a surface mesh was accepted for simulation";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(surface + ": not a valid tissue"));
    EXPECT_THAT(e.what(), HasSubstr("surface mesh"));
    EXPECT_THAT(e.what(), HasSubstr("--centroids"));
  }

  // The default tissue with no vertex clamped would float away under the probe.
  CellComplex loose = readTissue(defaultTissuePath());
  std::fill(loose.fixed.begin(), loose.fixed.end(), 0);
  const std::string path = ::testing::TempDir() + "tp_unclamped.ply";
  writePly(path, loose);
  EXPECT_NO_THROW(readTissue(path));
  try {
    readSimulationTissue(path);
    FAIL() << "an unclamped tissue was accepted for simulation";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ": no vertex is clamped"));
  }
  std::remove(path.c_str());
}
