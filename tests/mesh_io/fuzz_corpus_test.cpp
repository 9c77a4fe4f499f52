// The fuzzers' committed inputs, replayed in the ordinary suite: every seed is a valid file of its
// format (and is detected as such from its content), and every reproducer a fuzzer ever found
// (fuzz/regressions/<format>/, named after the bug) is now read or rejected with primseg::Error.

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "../src/file_io.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

namespace fs = std::filesystem;

const fs::path kFuzzDir = PRIMSEG_FUZZ_DIR;

struct FormatFolder {
  const char* folder;
  MeshFormat format;
};
constexpr FormatFolder kFolders[] = {{"off", MeshFormat::Off},
                                     {"obj", MeshFormat::Obj},
                                     {"ply", MeshFormat::Ply},
                                     {"stl", MeshFormat::Stl}};

std::vector<fs::path> files_in(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && entry.path().filename().string()[0] != '.')
      files.push_back(entry.path());
  return files;
}

std::span<const char> span_of(const detail::FileImage& image) {
  return {image.bytes.get(), image.size};
}

TEST(FuzzCorpus, EverySeedIsAValidMeshDetectedAsItsFormat) {
  int seeds = 0;
  for (const FormatFolder& folder : kFolders) {
    for (const fs::path& file : files_in(kFuzzDir / "corpus" / folder.folder)) {
      SCOPED_TRACE(file.string());
      const detail::FileImage image = detail::read_file(file);
      const Mesh mesh = read_mesh(span_of(image), folder.format, file.string());
      EXPECT_NO_THROW(mesh.validate());
      EXPECT_GT(mesh.face_count(), 0u);
      EXPECT_EQ(detect_mesh_format(span_of(image)), folder.format);
      EXPECT_EQ(read_mesh_detecting_format(span_of(image)).face_count(), mesh.face_count());
      ++seeds;
    }
  }
  EXPECT_GE(seeds, 12);
}

TEST(FuzzCorpus, EveryRegressionIsReadOrRejectedCleanly) {
  for (const FormatFolder& folder : kFolders) {
    for (const fs::path& file : files_in(kFuzzDir / "regressions" / folder.folder)) {
      SCOPED_TRACE(file.string());
      const detail::FileImage image = detail::read_file(file);
      for (const bool detect : {false, true}) {
        try {
          const Mesh mesh = detect ? read_mesh_detecting_format(span_of(image), "regression")
                                   : read_mesh(span_of(image), folder.format, "regression");
          EXPECT_NO_THROW(mesh.validate());
        } catch (const Error& error) {
          EXPECT_NE(std::string(error.what()).find("regression"), std::string::npos)
              << error.what();
        }
      }
    }
  }
}

TEST(DetectMeshFormat, TellsFormatsApartByContent) {
  const auto detect = [](std::string_view text) {
    return detect_mesh_format(std::span<const char>(text.data(), text.size()));
  };
  EXPECT_EQ(detect("ply\r\nformat ascii 1.0\r\n"), MeshFormat::Ply);
  EXPECT_EQ(detect("# comment\n\n  COFF\n3 1 0\n"), MeshFormat::Off);
  EXPECT_EQ(detect("# exported\nmtllib a.mtl\nv 0 0 0\n"), MeshFormat::Obj);
  EXPECT_EQ(detect("SOLID part\nfacet normal 0 0 1\n"), MeshFormat::Stl);
  // A binary STL is recognised by its size, whatever its header says.
  std::string binary(84 + 50, '\0');
  binary.replace(0, 5, "hello");
  binary[80] = 1;
  EXPECT_EQ(detect(binary), MeshFormat::Stl);
  binary.push_back('\0');
  EXPECT_EQ(detect(binary), std::nullopt);
  EXPECT_EQ(detect(""), std::nullopt);
  EXPECT_EQ(detect("plywood\n"), std::nullopt);
  EXPECT_EQ(detect("# only a comment\n"), std::nullopt);
}

TEST(DetectMeshFormat, APrefixRulesFormatsOutOnlyWhenNothingThatFollowsCouldBeDetected) {
  const auto ruled_out = [](std::string_view text,
                            std::uint64_t max_size = std::numeric_limits<std::uint64_t>::max()) {
    return mesh_format_ruled_out(std::span<const char>(text.data(), text.size()), max_size);
  };
  const auto detect = [](std::string_view text) {
    return detect_mesh_format(std::span<const char>(text.data(), text.size()));
  };
  // A binary STL header declaring `triangles`, then zeros up to `size` bytes.
  const auto binary_stl = [](std::uint32_t triangles, std::size_t size) {
    std::string text(std::max<std::size_t>(size, 84), '\0');
    for (int i = 0; i < 4; ++i) text[80 + i] = static_cast<char>(triangles >> (8 * i) & 0xff);
    return text;
  };
  // Endless zeros or markup: decided once the signature bytes are in, not at the end.
  EXPECT_FALSE(ruled_out(std::string(kMeshSignatureBytes - 1, '\0')));
  EXPECT_TRUE(ruled_out(std::string(kMeshSignatureBytes, '\0')));
  std::string page;
  while (page.size() < kMeshSignatureBytes) page += "<p>not a mesh</p>\n";
  // Bytes 80 to 83 of the page, "mesh", would be the triangle count of a binary STL of 87 GB.
  EXPECT_FALSE(ruled_out(page));
  EXPECT_TRUE(ruled_out(page, std::uint64_t{1} << 30));
  // A binary STL stays possible while the data is not longer than its header declares.
  EXPECT_FALSE(ruled_out(binary_stl(10000, kMeshSignatureBytes)));  // 500,084 bytes declared
  EXPECT_TRUE(ruled_out(binary_stl(10000, kMeshSignatureBytes), 500083));
  EXPECT_TRUE(ruled_out(binary_stl(1000, kMeshSignatureBytes)));  // 50,084
  // What it claims: when a prefix is ruled out, no continuation is detected as a mesh.
  const std::string continuations[] = {"", "OFF\n", std::string(1 << 20, '\0'),
                                       std::string(500084 - kMeshSignatureBytes, '\0')};
  for (const std::string& prefix :
       {std::string(kMeshSignatureBytes, '\0'), page, binary_stl(1000, kMeshSignatureBytes)}) {
    ASSERT_TRUE(ruled_out(prefix, std::uint64_t{1} << 30));
    for (const std::string& rest : continuations) EXPECT_EQ(detect(prefix + rest), std::nullopt);
  }
  EXPECT_EQ(detect(binary_stl(10000, kMeshSignatureBytes) + continuations[3]), MeshFormat::Stl);
  // No prefix of a mesh file of any format is ruled out (files larger than the signature bytes).
  const fs::path dir = testing::temp_directory("ruled-out");
  const Mesh mesh =
      make_shape("box_with_hole", {.tessellation = Tessellation::Uniform, .edge_length = 0.01})
          .mesh;
  for (const char* name : {"m.off", "m.obj", "m.ply", "m.stl"}) {
    SCOPED_TRACE(name);
    write_mesh(dir / name, mesh);
    const std::string text(detail::read_file(dir / name).view());
    ASSERT_GT(text.size(), 2 * kMeshSignatureBytes);
    ASSERT_TRUE(detect(text));
    for (std::size_t size = 0; size <= text.size();
         size += size < 2 * kMeshSignatureBytes ? 1 : 4099)
      if (ruled_out(std::string_view(text).substr(0, size))) {
        ADD_FAILURE() << "prefix of " << size << " bytes ruled out";
        break;
      }
  }
  fs::remove_all(dir);
}

TEST(DetectMeshFormat, UnknownContentIsAParseErrorNamingTheInput) {
  const std::string text = "<html>not a mesh</html>";
  try {
    read_mesh_detecting_format(std::span<const char>(text.data(), text.size()), "upload.bin");
    ADD_FAILURE() << "no exception";
  } catch (const ParseError& error) {
    EXPECT_NE(std::string(error.what()).find("upload.bin"), std::string::npos);
  }
}

TEST(DetectMeshFormat, EmptyContentIsAParseErrorSayingSo) {
  try {
    read_mesh_detecting_format(std::span<const char>(), "standard input");
    ADD_FAILURE() << "no exception";
  } catch (const ParseError& error) {
    EXPECT_EQ(std::string(error.what()), "standard input: empty, no mesh data");
  }
}

}  // namespace
}  // namespace primseg
