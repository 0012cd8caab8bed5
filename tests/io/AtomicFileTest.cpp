#include "io/AtomicFile.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "io/IoTestUtil.h"

namespace tp {
namespace {

using test::messageOf;
using test::readText;
using test::TempDir;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(AtomicFile, WritesAndReplaces) {
  TempDir dir;
  const std::string path = dir.file("out.txt");
  writeFileAtomically(path, std::string_view("first\n"));
  EXPECT_EQ(readText(path), "first\n");
  writeFileAtomically(path, [](std::ostream& os) { os << "second\nline\n"; });
  EXPECT_EQ(readText(path), "second\nline\n");
  EXPECT_THAT(dir.entries(), ElementsAre("out.txt"));  // no temporary file left
}

TEST(AtomicFile, MissingDirectoryThrowsNamingPathAndReason) {
  TempDir dir;
  const std::string path = dir.file("no/such/dir/out.txt");
  const std::string msg =
      messageOf<std::runtime_error>([&] { writeFileAtomically(path, std::string_view("x")); });
  EXPECT_THAT(msg, HasSubstr(path));
  EXPECT_THAT(msg, HasSubstr("No such file or directory"));
  EXPECT_TRUE(dir.entries().empty());
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "no"));
}

TEST(AtomicFile, ThrowingCallbackKeepsPreviousFile) {
  TempDir dir;
  const std::string path = dir.file("keep.txt");
  writeFileAtomically(path, std::string_view("precious\n"));
  EXPECT_THROW(writeFileAtomically(path,
                                   [](std::ostream& os) {
                                     os << "half written";
                                     throw std::logic_error("callback failed");
                                   }),
               std::logic_error);  // passed on unchanged
  EXPECT_EQ(readText(path), "precious\n");
  EXPECT_THAT(dir.entries(), ElementsAre("keep.txt"));
}

TEST(AtomicFile, FailedStreamKeepsPreviousFile) {
  TempDir dir;
  const std::string path = dir.file("keep.txt");
  writeFileAtomically(path, std::string_view("precious\n"));
  const std::string msg = messageOf<std::runtime_error>([&] {
    writeFileAtomically(path, [](std::ostream& os) {
      os << "partial";
      os.setstate(std::ios::badbit);  // as a full disk would
    });
  });
  EXPECT_THAT(msg, HasSubstr(path));
  EXPECT_THAT(msg, HasSubstr("writing failed"));
  EXPECT_EQ(readText(path), "precious\n");
  EXPECT_THAT(dir.entries(), ElementsAre("keep.txt"));
}

TEST(AtomicFile, DirectoryTargetIsRefused) {
  TempDir dir;
  std::filesystem::create_directory(dir.path() / "sub");
  const std::string msg = messageOf<std::runtime_error>(
      [&] { writeFileAtomically(dir.file("sub"), std::string_view("x")); });
  EXPECT_THAT(msg, HasSubstr("is a directory"));
  EXPECT_TRUE(std::filesystem::is_directory(dir.path() / "sub"));
}

TEST(AtomicFile, SymlinkIsKeptAndItsTargetReplaced) {
  TempDir dir;
  const std::string real = dir.file("real.txt"), link = dir.file("link.txt");
  writeFileAtomically(real, std::string_view("old"));
  std::filesystem::create_symlink(real, link);
  writeFileAtomically(link, std::string_view("new"));
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(readText(real), "new");
}

TEST(AtomicFile, KeepsPermissionsOfReplacedFile) {
  TempDir dir;
  const std::string path = dir.file("script.sh");
  writeFileAtomically(path, std::string_view("#!/bin/sh\n"));
  namespace fs = std::filesystem;
  fs::permissions(path, fs::perms::owner_all);
  writeFileAtomically(path, std::string_view("#!/bin/sh\necho\n"));
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::all, fs::perms::owner_all);
}

}  // namespace
}  // namespace tp
