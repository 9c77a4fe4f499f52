// Readers facing garbage: random bytes and mutated valid files must give a valid mesh or a
// primseg::Error, never a crash, a hang or another exception.

#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <string>

#include "mesh_io_test_helpers.hpp"

namespace primseg {
namespace {

using mesh_io_test::Bytes;
using mesh_io_test::parse;

/// Valid seeds for mutation, one per format (binary and ascii where both exist).
std::vector<std::pair<MeshFormat, std::string>> seeds() {
  Bytes ply;
  ply.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 2\nproperty list uchar int "
      "vertex_indices\nproperty uchar red\nend_header\n");
  for (const float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f}) ply.put(c);
  ply.put(std::uint8_t{3}).put(0).put(1).put(2).put(std::uint8_t{9});
  ply.put(std::uint8_t{3}).put(0).put(2).put(3).put(std::uint8_t{9});
  Bytes stl;
  stl.text(std::string(80, ' ')).put(std::uint32_t{2});
  for (int t = 0; t < 2; ++t) {
    for (int i = 0; i < 12; ++i) stl.put(static_cast<float>((i * 7 + t) % 3));
    stl.put(std::uint16_t{0});
  }
  return {
      {MeshFormat::Off, "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n4 0 1 2 3\n"},
      {MeshFormat::Obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1/1 3//2 -1\n"},
      {MeshFormat::Ply, ply.str()},
      {MeshFormat::Ply,
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
       "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
      {MeshFormat::Stl, stl.str()},
      {MeshFormat::Stl,
       "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
       "endloop\nendfacet\nendsolid s\n"},
  };
}

/// Parses and classifies: 1 = valid mesh (which must then satisfy the invariants), 0 = Error.
int parse_or_reject(const std::string& bytes, MeshFormat format) {
  try {
    const Mesh mesh = parse(bytes, format, "fuzz");
    EXPECT_NO_THROW(mesh.validate());
    return 1;
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("fuzz"), std::string::npos) << error.what();
    return 0;
  }
}

TEST(ReaderRobustness, RandomBytesNeverCrashOrHang) {
  std::mt19937_64 rng(20240601);
  const auto start = std::chrono::steady_clock::now();
  // Bytes drawn from an alphabet that often forms tokens, plus fully random ones.
  const std::string alphabet = "0123456789 \n\n.-+eEfvOFplyasci#/\r";
  for (const MeshFormat format :
       {MeshFormat::Off, MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Stl}) {
    for (int iteration = 0; iteration < 1500; ++iteration) {
      std::string bytes(rng() % 300, '\0');
      const bool textual = iteration % 2 == 0;
      for (char& c : bytes) {
        c = textual ? alphabet[rng() % alphabet.size()] : static_cast<char>(rng());
      }
      parse_or_reject(bytes, format);
    }
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
}

TEST(ReaderRobustness, MutatedValidFilesNeverCrashOrHang) {
  std::mt19937_64 rng(7);
  const auto start = std::chrono::steady_clock::now();
  for (const auto& [format, seed] : seeds()) {
    ASSERT_EQ(parse_or_reject(seed, format), 1) << seed;
    int accepted = 0;
    for (int iteration = 0; iteration < 2000; ++iteration) {
      std::string bytes = seed;
      const int mutations = 1 + static_cast<int>(rng() % 4);
      for (int m = 0; m < mutations && !bytes.empty(); ++m) {
        const std::size_t at = rng() % bytes.size();
        switch (rng() % 5) {
          case 0:
            bytes[at] = static_cast<char>(rng());
            break;  // Overwrite.
          case 1:
            bytes.erase(at, 1 + rng() % 8);
            break;  // Delete.
          case 2:
            bytes.resize(at);
            break;  // Truncate.
          case 3:
            bytes.insert(at, 1, "0123456789-. \n"[rng() % 14]);
            break;  // Insert.
          default:
            bytes[at] = static_cast<char>(bytes[at] ^ (1 << (rng() % 8)));
            break;
        }
      }
      accepted += parse_or_reject(bytes, format);
    }
    // Sanity: mutations are not so destructive that nothing ever parses.
    EXPECT_GT(accepted, 0);
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
}

}  // namespace
}  // namespace primseg
