// Offscreen renderer and PNG encoder. The PNG files are checked with an independent decoder
// written here (chunk CRCs, zlib header, stored and fixed-Huffman deflate blocks, Adler-32,
// scanline filters), so a test failure cannot come from sharing a bug with the encoder.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "primseg/error.hpp"
#include "primseg/mesh.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/render.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using Color = std::array<std::uint8_t, 3>;

// ------------------------------------------------------------------------------------------
// Reference PNG decoder
// ------------------------------------------------------------------------------------------

std::uint32_t reference_crc32(const std::string& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const char c : bytes) {
    crc ^= static_cast<std::uint8_t>(c);
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::uint32_t reference_adler32(const std::vector<std::uint8_t>& bytes) {
  std::uint32_t a = 1;
  std::uint32_t b = 0;
  for (const std::uint8_t byte : bytes) {
    a = (a + byte) % 65521;
    b = (b + a) % 65521;
  }
  return (b << 16) | a;
}

std::uint32_t read_big_endian(const std::string& bytes, std::size_t at) {
  if (at + 4 > bytes.size()) throw std::runtime_error("truncated at byte " + std::to_string(at));
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i)
    value = (value << 8) | static_cast<std::uint8_t>(bytes[at + i]);
  return value;
}

class BitReader {
 public:
  explicit BitReader(const std::vector<std::uint8_t>& bytes) : bytes_(bytes) {}
  std::uint32_t bit() {
    if (position_ / 8 >= bytes_.size()) throw std::runtime_error("deflate stream truncated");
    const std::uint32_t value = (bytes_[position_ / 8] >> (position_ % 8)) & 1u;
    ++position_;
    return value;
  }
  // Data fields: least significant bit first.
  std::uint32_t bits(int count) {
    std::uint32_t value = 0;
    for (int i = 0; i < count; ++i) value |= bit() << i;
    return value;
  }
  // Huffman codes: most significant bit first.
  std::uint32_t code(int count) {
    std::uint32_t value = 0;
    for (int i = 0; i < count; ++i) value = (value << 1) | bit();
    return value;
  }
  void align_to_byte() { position_ = (position_ + 7) / 8 * 8; }
  std::size_t byte_position() const { return position_ / 8; }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::size_t position_ = 0;
};

std::uint32_t fixed_literal_or_length(BitReader& reader) {
  std::uint32_t code = reader.code(7);
  if (code <= 23) return 256 + code;
  code = (code << 1) | reader.bit();
  if (code >= 0x30 && code <= 0xbf) return code - 0x30;
  if (code >= 0xc0 && code <= 0xc7) return 280 + (code - 0xc0);
  code = (code << 1) | reader.bit();
  if (code >= 0x190 && code <= 0x1ff) return 144 + (code - 0x190);
  throw std::runtime_error("invalid fixed Huffman code");
}

struct Inflated {
  std::vector<std::uint8_t> data;
  std::set<std::uint32_t> block_types;
  std::size_t consumed_bytes = 0;
};

// Inflate for the block types encode_png may write: stored (0) and fixed Huffman (1).
Inflated inflate(const std::vector<std::uint8_t>& stream) {
  static constexpr std::array<std::uint32_t, 29> kLengthBase{
      3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
      31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
  static constexpr std::array<int, 29> kLengthExtra{0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                    2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
  static constexpr std::array<std::uint32_t, 30> kDistanceBase{
      1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
      193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
  static constexpr std::array<int, 30> kDistanceExtra{0, 0, 0,  0,  1,  1,  2,  2,  3,  3,
                                                      4, 4, 5,  5,  6,  6,  7,  7,  8,  8,
                                                      9, 9, 10, 10, 11, 11, 12, 12, 13, 13};
  Inflated result;
  BitReader reader(stream);
  bool final_block = false;
  while (!final_block) {
    final_block = reader.bit() == 1;
    const std::uint32_t type = reader.bits(2);
    result.block_types.insert(type);
    if (type == 0) {
      reader.align_to_byte();
      const std::uint32_t length = reader.bits(16);
      const std::uint32_t complement = reader.bits(16);
      if ((length ^ 0xffffu) != complement) throw std::runtime_error("stored block NLEN mismatch");
      for (std::uint32_t i = 0; i < length; ++i) {
        result.data.push_back(static_cast<std::uint8_t>(reader.bits(8)));
      }
    } else if (type == 1) {
      for (;;) {
        const std::uint32_t symbol = fixed_literal_or_length(reader);
        if (symbol < 256) {
          result.data.push_back(static_cast<std::uint8_t>(symbol));
          continue;
        }
        if (symbol == 256) break;
        if (symbol > 285) throw std::runtime_error("invalid length symbol");
        const std::size_t length_code = symbol - 257;
        const std::uint32_t length =
            kLengthBase[length_code] + reader.bits(kLengthExtra[length_code]);
        const std::uint32_t distance_code = reader.code(5);
        if (distance_code >= 30) throw std::runtime_error("invalid distance code");
        const std::uint32_t distance =
            kDistanceBase[distance_code] + reader.bits(kDistanceExtra[distance_code]);
        if (distance > result.data.size() || distance > 32768) {
          throw std::runtime_error("distance beyond the window");
        }
        for (std::uint32_t i = 0; i < length; ++i) {
          result.data.push_back(result.data[result.data.size() - distance]);
        }
      }
    } else {
      throw std::runtime_error("unexpected deflate block type " + std::to_string(type));
    }
  }
  reader.align_to_byte();
  result.consumed_bytes = reader.byte_position();
  return result;
}

struct DecodedPng {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
  std::vector<std::string> chunk_types;
  std::set<std::uint32_t> block_types;
};

int paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  return pb <= pc ? b : c;
}

DecodedPng decode_png(const std::string& png) {
  static const std::string kSignature("\x89PNG\r\n\x1a\n", 8);
  if (png.compare(0, 8, kSignature) != 0) throw std::runtime_error("no PNG signature");
  DecodedPng decoded;
  std::string idat;
  std::size_t at = 8;
  while (at < png.size()) {
    const std::uint32_t length = read_big_endian(png, at);
    if (at + 12 + length > png.size()) throw std::runtime_error("chunk overruns the file");
    const std::string type_and_data = png.substr(at + 4, 4 + length);
    const std::string type = type_and_data.substr(0, 4);
    const std::string data = type_and_data.substr(4);
    if (reference_crc32(type_and_data) != read_big_endian(png, at + 8 + length)) {
      throw std::runtime_error("bad CRC in chunk " + type);
    }
    decoded.chunk_types.push_back(type);
    if (type == "IHDR") {
      if (length != 13) throw std::runtime_error("IHDR length");
      decoded.width = static_cast<int>(read_big_endian(data, 0));
      decoded.height = static_cast<int>(read_big_endian(data, 4));
      if (data.substr(8) != std::string("\x08\x02\x00\x00\x00", 5)) {
        throw std::runtime_error(
            "expected 8-bit truecolour, deflate, adaptive filter, no interlace");
      }
    } else if (type == "IDAT") {
      idat += data;
    }
    at += 12 + length;
  }

  const std::vector<std::uint8_t> stream(idat.begin(), idat.end());
  if (stream.size() < 6) throw std::runtime_error("zlib stream too short");
  if ((stream[0] & 0x0f) != 8 || (stream[0] >> 4) > 7) throw std::runtime_error("zlib CMF");
  if (((stream[0] << 8) | stream[1]) % 31 != 0) throw std::runtime_error("zlib FCHECK");
  if (stream[1] & 0x20) throw std::runtime_error("zlib preset dictionary");
  const std::vector<std::uint8_t> deflated(stream.begin() + 2, stream.end());
  const Inflated inflated = inflate(deflated);
  decoded.block_types = inflated.block_types;
  if (inflated.consumed_bytes + 4 != deflated.size()) {
    throw std::runtime_error("trailing bytes after the deflate stream");
  }
  std::uint32_t adler = 0;
  for (std::size_t i = 0; i < 4; ++i) adler = (adler << 8) | deflated[inflated.consumed_bytes + i];
  if (adler != reference_adler32(inflated.data)) throw std::runtime_error("bad Adler-32");

  const std::size_t stride = static_cast<std::size_t>(decoded.width) * 3;
  if (inflated.data.size() != (stride + 1) * static_cast<std::size_t>(decoded.height)) {
    throw std::runtime_error("decompressed size does not match IHDR");
  }
  std::vector<std::uint8_t> previous(stride, 0);
  for (int y = 0; y < decoded.height; ++y) {
    const std::uint8_t* line = inflated.data.data() + static_cast<std::size_t>(y) * (stride + 1);
    const int filter = line[0];
    std::vector<std::uint8_t> row(line + 1, line + 1 + stride);
    for (std::size_t i = 0; i < stride; ++i) {
      const int left = i >= 3 ? row[i - 3] : 0;
      const int above = previous[i];
      const int upper_left = i >= 3 ? previous[i - 3] : 0;
      int prediction = 0;
      switch (filter) {
        case 0:
          prediction = 0;
          break;
        case 1:
          prediction = left;
          break;
        case 2:
          prediction = above;
          break;
        case 3:
          prediction = (left + above) / 2;
          break;
        case 4:
          prediction = paeth(left, above, upper_left);
          break;
        default:
          throw std::runtime_error("bad filter type");
      }
      row[i] = static_cast<std::uint8_t>(row[i] + prediction);
    }
    decoded.rgb.insert(decoded.rgb.end(), row.begin(), row.end());
    previous = row;
  }
  return decoded;
}

// ------------------------------------------------------------------------------------------
// Meshes and picture helpers
// ------------------------------------------------------------------------------------------

constexpr Color kRed{255, 0, 0};
constexpr Color kCyan{0, 255, 255};
constexpr Color kGreen{0, 255, 0};
constexpr Color kMagenta{255, 0, 255};
constexpr Color kBlue{0, 0, 255};
constexpr Color kYellow{255, 255, 0};
constexpr Color kWhite{255, 255, 255};

// Unit cube as six quads in the order +X, -X, +Y, -Y, +Z, -Z.
Mesh unit_cube() {
  std::vector<Vec3> positions;
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z) positions.push_back({double(x), double(y), double(z)});
  auto v = [](int x, int y, int z) { return static_cast<std::uint32_t>(4 * x + 2 * y + z); };
  std::vector<std::uint32_t> loops{
      v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1),  // +X
      v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0),  // -X
      v(0, 1, 0), v(0, 1, 1), v(1, 1, 1), v(1, 1, 0),  // +Y
      v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1),  // -Y
      v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1),  // +Z
      v(0, 0, 0), v(0, 1, 0), v(1, 1, 0), v(1, 0, 0),  // -Z
  };
  return Mesh::from_polygons(std::move(positions), {0, 4, 8, 12, 16, 20, 24}, std::move(loops));
}

const std::vector<Color> kCubeSideColors{kRed, kCyan, kGreen, kMagenta, kBlue, kYellow};

// Rectangle [0, 2] x [0, 1] in the plane z = 0, as a left and a right unit square.
Mesh split_rectangle() {
  return Mesh::from_polygons({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}},
                             {0, 4, 8}, {0, 1, 4, 3, 1, 2, 5, 4});
}

Mesh uv_sphere(int rows, int cols) {
  return testing::grid_mesh(rows, cols, [](double u, double v) {
    const double theta = std::numbers::pi * u;
    const double phi = 2.0 * std::numbers::pi * v;
    return Vec3{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
  });
}

Color pixel(const std::vector<std::uint8_t>& rgb, const RenderOptions& options, int x, int y) {
  const std::size_t at = (static_cast<std::size_t>(y) * options.width + x) * 3;
  return {rgb[at], rgb[at + 1], rgb[at + 2]};
}

std::map<Color, int> color_histogram(const std::vector<std::uint8_t>& rgb) {
  std::map<Color, int> histogram;
  for (std::size_t at = 0; at < rgb.size(); at += 3)
    ++histogram[{rgb[at], rgb[at + 1], rgb[at + 2]}];
  return histogram;
}

int count_not(const std::vector<std::uint8_t>& rgb, const Color& background) {
  int count = 0;
  for (std::size_t at = 0; at < rgb.size(); at += 3) {
    if (Color{rgb[at], rgb[at + 1], rgb[at + 2]} != background) ++count;
  }
  return count;
}

// The colour the renderer's documented shading gives `base` on a face with unit normal
// `normal`.
Color shaded(const Color& base, const Vec3& normal, const RenderOptions& options) {
  const auto& d = options.view_direction;
  const double facing = std::abs(normal[0] * d[0] + normal[1] * d[1] + normal[2] * d[2]) /
                        std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double intensity = options.light_ambient + (1.0 - options.light_ambient) * facing;
  Color result{};
  for (int c = 0; c < 3; ++c)
    result[c] = static_cast<std::uint8_t>(std::lround(base[c] * intensity));
  return result;
}

// ------------------------------------------------------------------------------------------
// render_mesh
// ------------------------------------------------------------------------------------------

TEST(RenderMesh, CubeCentreIsCoveredAndCornersAreBackground) {
  const RenderOptions options;  // default 800x600, 2x2 supersampling
  const std::vector<std::uint8_t> rgb = render_mesh(unit_cube(), kCubeSideColors, options);
  ASSERT_EQ(rgb.size(), std::size_t{800} * 600 * 3);
  EXPECT_NE(pixel(rgb, options, 400, 300), kWhite);
  EXPECT_EQ(pixel(rgb, options, 0, 0), kWhite);
  EXPECT_EQ(pixel(rgb, options, 799, 0), kWhite);
  EXPECT_EQ(pixel(rgb, options, 0, 599), kWhite);
  EXPECT_EQ(pixel(rgb, options, 799, 599), kWhite);
}

TEST(RenderMesh, CubeShowsExactlyTheThreeSidesFacingTheEyeWithLambertShading) {
  RenderOptions options;
  options.width = 240;
  options.height = 180;
  options.supersample = 1;  // no blending: every pixel is one face's shaded colour or background
  const std::vector<std::uint8_t> rgb = render_mesh(unit_cube(), kCubeSideColors, options);
  const std::map<Color, int> histogram = color_histogram(rgb);

  // The default eye is on the +X +Y +Z side of the model.
  const Color red = shaded(kRed, {1, 0, 0}, options);
  const Color green = shaded(kGreen, {0, 1, 0}, options);
  const Color blue = shaded(kBlue, {0, 0, 1}, options);
  std::set<Color> seen;
  for (const auto& [color, count] : histogram) seen.insert(color);
  EXPECT_EQ(seen, (std::set<Color>{kWhite, red, green, blue}));
  const int pixels = options.width * options.height;
  for (const Color& side : {red, green, blue}) {
    ASSERT_TRUE(histogram.count(side));
    EXPECT_GT(histogram.at(side), pixels / 50);
  }
  // The cube's outline fills the picture but for the 5% margins: its pixels are a sizeable part.
  EXPECT_GT(pixels - histogram.at(kWhite), pixels / 4);
}

TEST(RenderMesh, FullAmbientLightGivesTheFaceColoursExactly) {
  RenderOptions options;
  options.width = 160;
  options.height = 120;
  options.supersample = 1;
  options.light_ambient = 1.0;
  const std::map<Color, int> histogram =
      color_histogram(render_mesh(unit_cube(), kCubeSideColors, options));
  std::set<Color> seen;
  for (const auto& [color, count] : histogram) seen.insert(color);
  EXPECT_EQ(seen, (std::set<Color>{kWhite, kRed, kGreen, kBlue}));
}

// A small picture of the cube, one sample per pixel: lines cover whole pixels.
RenderOptions small_unsampled_picture() {
  RenderOptions options;
  options.width = 240;
  options.height = 180;
  options.supersample = 1;
  return options;
}

TEST(RenderMesh, EdgesDarkenPixelsAlongTheTriangleEdgesOnly) {
  RenderOptions options = small_unsampled_picture();
  const std::vector<std::uint8_t> plain = render_mesh(unit_cube(), kCubeSideColors, options);
  options.edges = true;
  const std::vector<std::uint8_t> outlined = render_mesh(unit_cube(), kCubeSideColors, options);

  int darkened = 0;
  int covered = 0;
  for (std::size_t at = 0; at < plain.size(); at += 3) {
    const Color before{plain[at], plain[at + 1], plain[at + 2]};
    const Color after{outlined[at], outlined[at + 1], outlined[at + 2]};
    if (before == kWhite) {
      EXPECT_EQ(after, kWhite) << "edges must not spill onto the background";
      continue;
    }
    ++covered;
    if (after == before) continue;
    ++darkened;
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(after[c], before[c] + 1);
      EXPECT_EQ(after[c] == 0, before[c] == 0) << "an edge keeps its face's hue";
    }
  }
  // Outline plus one diagonal per visible quad, about one pixel wide.
  EXPECT_GT(darkened, 200);
  EXPECT_LT(darkened, covered / 4);
}

// Borders are the edges between colours: the cube's outline and the edges between its sides, not
// the diagonals inside each side; a cube of one colour, closed, has none.
TEST(RenderMesh, BordersDarkenOnlyTheEdgesBetweenColours) {
  RenderOptions options = small_unsampled_picture();
  const std::vector<std::uint8_t> plain = render_mesh(unit_cube(), kCubeSideColors, options);
  options.edges = true;
  const std::vector<std::uint8_t> all_edges = render_mesh(unit_cube(), kCubeSideColors, options);
  options.edges = false;
  options.borders = true;
  const std::vector<std::uint8_t> borders = render_mesh(unit_cube(), kCubeSideColors, options);
  int by_borders = 0, by_edges = 0;
  for (std::size_t at = 0; at < plain.size(); at += 3) {
    const Color before{plain[at], plain[at + 1], plain[at + 2]};
    const Color edge{all_edges[at], all_edges[at + 1], all_edges[at + 2]};
    const Color border{borders[at], borders[at + 1], borders[at + 2]};
    by_edges += edge != before;
    if (border == before) continue;
    ++by_borders;
    EXPECT_EQ(border, edge) << "a border is drawn as the same line as the edge";
  }
  EXPECT_GT(by_borders, 150);
  EXPECT_LT(by_borders, by_edges - 100) << "the diagonals inside the sides are not borders";

  const std::vector<Color> one_colour(6, kGreen);
  EXPECT_EQ(render_mesh(unit_cube(), one_colour, options), [&] {
    RenderOptions without = options;
    without.borders = false;
    return render_mesh(unit_cube(), one_colour, without);
  }());

  // An open rectangle in two colours: its outline and the line between the colours.
  options.width = 200;
  options.height = 100;
  options.view_direction = {0, 0, -1};
  options.supersample = 2;  // one sample per pixel can straddle a half-pixel line at the outline
  const std::vector<Color> two{kRed, kBlue};
  const std::vector<std::uint8_t> split = render_mesh(split_rectangle(), two, options);
  options.borders = false;
  const std::vector<std::uint8_t> unlined = render_mesh(split_rectangle(), two, options);
  const auto lined = [&](int x, int y) {
    return pixel(split, options, x, y) != pixel(unlined, options, x, y);
  };
  EXPECT_FALSE(lined(50, 50));
  int middle = 0;
  for (int x = 90; x <= 110; ++x) middle += lined(x, 50);
  EXPECT_GE(middle, 1) << "the line between the two colours";
  int outline = 0;
  for (int y = 0; y < 100; ++y) outline += lined(50, y);
  EXPECT_GE(outline, 2) << "the top and bottom of the open rectangle";
}

TEST(RenderMesh, TwoColourSplitRendersBothHues) {
  RenderOptions options;
  options.width = 200;
  options.height = 100;
  options.view_direction = {0, 0, -1};  // face on: full intensity
  const std::vector<Color> colors{kRed, kBlue};
  const std::vector<std::uint8_t> rgb = render_mesh(split_rectangle(), colors, options);
  EXPECT_EQ(pixel(rgb, options, 50, 50), kRed);
  EXPECT_EQ(pixel(rgb, options, 150, 50), kBlue);
  // Mirrored if seen from behind (two-sided, same brightness).
  options.view_direction = {0, 0, 1};
  const std::vector<std::uint8_t> behind = render_mesh(split_rectangle(), colors, options);
  EXPECT_EQ(pixel(behind, options, 50, 50), kBlue);
  EXPECT_EQ(pixel(behind, options, 150, 50), kRed);
}

TEST(RenderMesh, EmptyColourSpanPaintsLightGrey) {
  RenderOptions options;
  options.width = 200;
  options.height = 100;
  options.view_direction = {0, 0, -1};
  const std::vector<std::uint8_t> rgb = render_mesh(split_rectangle(), {}, options);
  const Color centre = pixel(rgb, options, 100, 50);
  EXPECT_EQ(centre[0], centre[1]);
  EXPECT_EQ(centre[1], centre[2]);
  EXPECT_GE(centre[0], 150);
  EXPECT_LT(centre[0], 255);
  for (std::size_t at = 0; at < rgb.size(); at += 3) {
    ASSERT_TRUE(rgb[at] == rgb[at + 1] && rgb[at + 1] == rgb[at + 2]) << "pixel " << at / 3;
  }

  // And grey on a coloured background too.
  options.background = {10, 20, 30};
  const std::vector<std::uint8_t> dark = render_mesh(split_rectangle(), {}, options);
  EXPECT_EQ(pixel(dark, options, 100, 50), centre);
  EXPECT_EQ(pixel(dark, options, 0, 0), (Color{10, 20, 30}));
}

TEST(RenderMesh, IsDeterministic) {
  const Mesh sphere = uv_sphere(60, 90);
  const std::vector<Color> colors = distinct_colors(sphere.face_count());
  RenderOptions options;
  options.edges = true;
  EXPECT_EQ(render_mesh(sphere, colors, options), render_mesh(sphere, colors, options));
}

TEST(RenderMesh, ClosedSphereHasNoPinholes) {
  // Shared edges must be filled exactly once: with floating-point coverage tests, samples on an
  // edge shared by two triangles can be missed by both and show the background through.
  const Mesh sphere = uv_sphere(97, 131);
  RenderOptions options;
  options.width = 400;
  options.height = 300;
  options.supersample = 1;
  for (const auto& view : {std::array<double, 3>{0, 0, -1}, std::array<double, 3>{0.3, -0.2, -1},
                           std::array<double, 3>{1, 1, 1}}) {
    options.view_direction = view;
    const std::vector<std::uint8_t> rgb = render_mesh(sphere, {}, options);
    // The framing fits the bounding cube's outline, so the sphere's silhouette, a disc at the
    // centre, has a radius of 83 pixels or more for these views.
    const double radius = 0.22 * options.height;
    for (int y = 0; y < options.height; ++y) {
      for (int x = 0; x < options.width; ++x) {
        const double dx = x + 0.5 - 0.5 * options.width;
        const double dy = y + 0.5 - 0.5 * options.height;
        if (dx * dx + dy * dy < radius * radius) {
          ASSERT_NE(pixel(rgb, options, x, y), kWhite) << "hole at " << x << "," << y;
        }
      }
    }
  }
}

TEST(RenderMesh, JitteredGridHasNoPinholes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  const int n = 40;
  Mesh grid = testing::grid_mesh(
      n, n,
      [](double u, double v) {
        return Vec3{u, v, 0.0};
      },
      true);
  for (Vec3& p : grid.positions) {
    const bool border = p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0;
    if (!border) {
      p[0] += jitter(rng) / n;
      p[1] += jitter(rng) / n;
    }
  }
  RenderOptions options;
  options.width = 300;
  options.height = 300;
  options.supersample = 1;
  options.view_direction = {0, 0, -1};
  const std::vector<std::uint8_t> rgb = render_mesh(grid, {}, options);
  // The unit square spans 90% of the picture: [15, 285) in both directions.
  for (int y = 17; y < 283; ++y) {
    for (int x = 17; x < 283; ++x) {
      ASSERT_NE(pixel(rgb, options, x, y), kWhite) << "hole at " << x << "," << y;
    }
  }
  EXPECT_EQ(pixel(rgb, options, 5, 150), kWhite);
}

TEST(RenderMesh, EdgesThroughSampleCentresLeaveNoPinholes) {
  // The unit square spans 171 of 190 pixels from x = 9.5, so the vertices of a 19 x 19 grid, its
  // edges and its diagonals all pass through pixel centres: only the top-left rule fills them.
  const Mesh grid = testing::grid_mesh(19, 19, [](double u, double v) { return Vec3{u, v, 0.0}; });
  RenderOptions options;
  options.width = 190;
  options.height = 190;
  options.supersample = 1;
  options.view_direction = {0, 0, -1};
  const std::vector<std::uint8_t> rgb = render_mesh(grid, {}, options);
  for (int y = 10; y < 180; ++y) {
    for (int x = 10; x < 180; ++x) {
      ASSERT_NE(pixel(rgb, options, x, y), kWhite) << "hole at " << x << "," << y;
    }
  }
  // Samples exactly on the outline belong to the square on its top and left sides only.
  EXPECT_NE(pixel(rgb, options, 9, 100), kWhite);
  EXPECT_NE(pixel(rgb, options, 100, 9), kWhite);
  EXPECT_EQ(pixel(rgb, options, 180, 100), kWhite);
  EXPECT_EQ(pixel(rgb, options, 100, 180), kWhite);
  EXPECT_EQ(pixel(rgb, options, 8, 100), kWhite);
}

TEST(RenderMesh, NearerFacesHideFartherOnes) {
  // Two parallel squares, the red one nearer to the eye, drawn in both orders.
  std::vector<Vec3> positions{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
                              {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  RenderOptions options;
  options.width = 100;
  options.height = 100;
  options.view_direction = {0, 0, -1};  // the eye is on the +z side
  for (const bool near_first : {true, false}) {
    const std::vector<std::uint32_t> near_loop{0, 1, 2, 3};
    const std::vector<std::uint32_t> far_loop{4, 5, 6, 7};
    std::vector<std::uint32_t> loops = near_first ? near_loop : far_loop;
    loops.insert(loops.end(), (near_first ? far_loop : near_loop).begin(),
                 (near_first ? far_loop : near_loop).end());
    const Mesh mesh = Mesh::from_polygons(positions, {0, 4, 8}, loops);
    const std::vector<Color> colors =
        near_first ? std::vector<Color>{kRed, kBlue} : std::vector<Color>{kBlue, kRed};
    EXPECT_EQ(pixel(render_mesh(mesh, colors, options), options, 50, 50), kRed);
  }
}

TEST(RenderMesh, DegenerateTrianglesDrawNothing) {
  const Mesh cube = unit_cube();
  std::vector<Vec3> positions = cube.positions;
  positions.push_back({0.5, 0.0, 0.0});  // on the edge from (0,0,0) to (1,0,0)
  std::vector<Triangle> triangles = cube.triangles;
  triangles.push_back({0, 0, 4});  // repeated vertex
  triangles.push_back({0, 8, 4});  // collinear
  triangles.push_back({3, 3, 3});  // a point
  const Mesh with_degenerates = Mesh::from_triangles(positions, triangles);
  RenderOptions options;
  options.width = 160;
  options.height = 120;
  EXPECT_EQ(render_mesh(with_degenerates, {}, options),
            render_mesh(Mesh::from_triangles(cube.positions, cube.triangles), {}, options));
}

TEST(RenderMesh, PictureDoesNotDependOnScaleOrPosition) {
  const Mesh cube = unit_cube();
  Mesh moved = cube;
  for (Vec3& p : moved.positions) p = {p[0] * 1e4 + 3e7, p[1] * 1e4 - 1e6, p[2] * 1e4 + 12345.5};
  Mesh tiny = cube;
  for (Vec3& p : tiny.positions) p = {p[0] * 1e-6, p[1] * 1e-6 - 1.0, p[2] * 1e-6};
  RenderOptions options;
  options.width = 200;
  options.height = 150;
  const std::vector<std::uint8_t> reference = render_mesh(cube, kCubeSideColors, options);
  for (const Mesh* other : {&moved, &tiny}) {
    const std::vector<std::uint8_t> rgb = render_mesh(*other, kCubeSideColors, options);
    int different = 0;
    for (std::size_t at = 0; at < rgb.size(); at += 3) {
      if (!std::equal(rgb.begin() + at, rgb.begin() + at + 3, reference.begin() + at)) ++different;
    }
    // Rounding of the snapped vertices may move an edge pixel's blend; nothing more.
    EXPECT_LT(different, options.width * options.height / 200);
  }
}

TEST(RenderMesh, FrameBoxFixesTheFraming) {
  const Mesh cube = unit_cube();
  RenderOptions options;
  options.width = 200;
  options.height = 150;
  const std::vector<std::uint8_t> automatic = render_mesh(cube, kCubeSideColors, options);
  options.frame_box = std::array<Vec3, 2>{Vec3{0, 0, 0}, Vec3{1, 1, 1}};
  EXPECT_EQ(render_mesh(cube, kCubeSideColors, options), automatic);

  // Twice the box: the cube appears half as large, a quarter of the pixels.
  options.frame_box = std::array<Vec3, 2>{Vec3{-0.5, -0.5, -0.5}, Vec3{1.5, 1.5, 1.5}};
  const double ratio = double(count_not(render_mesh(cube, kCubeSideColors, options), kWhite)) /
                       count_not(automatic, kWhite);
  EXPECT_NEAR(ratio, 0.25, 0.03);

  // A box smaller than the mesh crops it: the whole picture is covered.
  options.frame_box = std::array<Vec3, 2>{Vec3{0.45, 0.45, 0.45}, Vec3{0.55, 0.55, 0.55}};
  EXPECT_EQ(count_not(render_mesh(cube, kCubeSideColors, options), kWhite),
            options.width * options.height);
}

TEST(RenderMesh, UpParallelToTheViewFallsBackToAnotherAxis) {
  RenderOptions options;
  options.width = 100;
  options.height = 100;
  options.view_direction = {0, -1, 0};  // looking straight down the default up
  const std::vector<std::uint8_t> rgb = render_mesh(unit_cube(), kCubeSideColors, options);
  EXPECT_EQ(pixel(rgb, options, 50, 50), kGreen);  // the top (+Y) side, face on
}

TEST(RenderMesh, EmptyMeshIsBackgroundOnly) {
  RenderOptions options;
  options.width = 7;
  options.height = 5;
  options.background = {1, 2, 3};
  const std::vector<std::uint8_t> rgb = render_mesh(Mesh{}, {}, options);
  ASSERT_EQ(rgb.size(), std::size_t{7} * 5 * 3);
  EXPECT_EQ(count_not(rgb, {1, 2, 3}), 0);
}

TEST(RenderMesh, RejectsBadArguments) {
  const Mesh cube = unit_cube();
  const std::vector<Color> too_few(5, kRed);
  EXPECT_THROW(render_mesh(cube, too_few), InvalidInputError);

  auto expect_rejected = [&](auto&& change) {
    RenderOptions options;
    change(options);
    EXPECT_THROW(render_mesh(cube, {}, options), InvalidInputError);
  };
  expect_rejected([](RenderOptions& o) { o.width = 0; });
  expect_rejected([](RenderOptions& o) { o.height = 20000; });
  expect_rejected([](RenderOptions& o) { o.supersample = 0; });
  expect_rejected([](RenderOptions& o) { o.supersample = 9; });
  expect_rejected([](RenderOptions& o) { o.light_ambient = 1.5; });
  expect_rejected([](RenderOptions& o) { o.light_ambient = std::nan(""); });
  expect_rejected([](RenderOptions& o) { o.view_direction = {0, 0, 0}; });
  expect_rejected([](RenderOptions& o) { o.view_direction = {std::nan(""), 0, 1}; });
  expect_rejected([](RenderOptions& o) {
    o.frame_box = std::array<Vec3, 2>{Vec3{1, 0, 0}, Vec3{0, 1, 1}};
  });

  Mesh broken = cube;
  broken.triangles[3][1] = 99;
  EXPECT_THROW(render_mesh(broken, {}), InvalidInputError);
}

TEST(RenderMesh, FandiskCoversAPlausibleShareOfThePicture) {
  const Mesh fandisk = read_mesh(testing::cgal_mesh("fandisk.off"));
  const std::vector<Color> colors = distinct_colors(fandisk.face_count());
  const RenderOptions options;
  const std::vector<std::uint8_t> rgb = render_mesh(fandisk, colors, options);
  const double covered = double(count_not(rgb, kWhite)) / (options.width * options.height);
  EXPECT_GT(covered, 0.25);
  EXPECT_LT(covered, 0.8);
  EXPECT_EQ(rgb, render_mesh(fandisk, colors, options));
}

// ------------------------------------------------------------------------------------------
// PNG
// ------------------------------------------------------------------------------------------

std::vector<std::uint8_t> random_bytes(std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint8_t> bytes(count);
  for (std::uint8_t& b : bytes) b = static_cast<std::uint8_t>(rng() >> 56);
  return bytes;
}

void expect_round_trip(const std::vector<std::uint8_t>& rgb, int width, int height) {
  const std::string png = encode_png(rgb, width, height);
  const DecodedPng decoded = decode_png(png);
  EXPECT_EQ(decoded.width, width);
  EXPECT_EQ(decoded.height, height);
  EXPECT_TRUE(decoded.rgb == rgb) << width << "x" << height;
}

TEST(EncodePng, HasSignatureHeaderAndValidChunks) {
  const std::vector<std::uint8_t> rgb = random_bytes(5 * 3 * 3, 1);
  const std::string png = encode_png(rgb, 5, 3);
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // IHDR comes first with width and height big-endian.
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(read_big_endian(png, 16), 5u);
  EXPECT_EQ(read_big_endian(png, 20), 3u);

  const DecodedPng decoded = decode_png(png);  // checks every CRC
  ASSERT_GE(decoded.chunk_types.size(), 3u);
  EXPECT_EQ(decoded.chunk_types.front(), "IHDR");
  EXPECT_EQ(decoded.chunk_types.back(), "IEND");
  for (std::size_t i = 1; i + 1 < decoded.chunk_types.size(); ++i) {
    EXPECT_EQ(decoded.chunk_types[i], "IDAT");
  }
  EXPECT_EQ(decoded.rgb, rgb);
}

TEST(EncodePng, RenderedPictureCompressesWithFixedHuffmanBlocks) {
  RenderOptions options;
  options.width = 320;
  options.height = 240;
  options.edges = true;
  const std::vector<std::uint8_t> rgb = render_mesh(unit_cube(), kCubeSideColors, options);
  const std::string png = encode_png(rgb, options.width, options.height);
  const DecodedPng decoded = decode_png(png);
  EXPECT_EQ(decoded.rgb, rgb);
  EXPECT_EQ(decoded.block_types, (std::set<std::uint32_t>{1}));
  EXPECT_LT(png.size(), rgb.size() / 10);
}

TEST(EncodePng, NoiseFallsBackToStoredBlocks) {
  // 200 x 150 x 3 = 90000 bytes: more than one stored block (at most 65535 bytes each).
  const std::vector<std::uint8_t> rgb = random_bytes(200 * 150 * 3, 2);
  const std::string png = encode_png(rgb, 200, 150);
  const DecodedPng decoded = decode_png(png);
  EXPECT_EQ(decoded.rgb, rgb);
  EXPECT_EQ(decoded.block_types, (std::set<std::uint32_t>{0}));
  EXPECT_LT(png.size(), rgb.size() + 400);  // filter bytes and headers
}

TEST(EncodePng, RoundTripsStructuredPicturesOfManyShapes) {
  // Rows copied from earlier rows with a shift and a few changed bytes give matches of every
  // length and distance, including distances near the 32 KiB window.
  std::mt19937_64 rng(3);
  for (const auto& [width, height] :
       std::vector<std::pair<int, int>>{{1, 1}, {1, 300}, {3000, 2}, {257, 129}, {4000, 9}}) {
    const std::size_t stride = static_cast<std::size_t>(width) * 3;
    std::vector<std::uint8_t> rgb = random_bytes(stride, rng());
    for (int y = 1; y < height; ++y) {
      const std::size_t source_row =
          std::uniform_int_distribution<std::size_t>(0, static_cast<std::size_t>(y) - 1)(rng);
      const std::size_t shift = std::uniform_int_distribution<std::size_t>(0, 7)(rng);
      for (std::size_t i = 0; i < stride; ++i) {
        rgb.push_back(rgb[source_row * stride + (i + shift) % stride]);
        if (rng() % 50 == 0) rgb.back() = static_cast<std::uint8_t>(rng());
      }
    }
    expect_round_trip(rgb, width, height);
  }
  // Flat colour: the longest matches at distance 1 and 3.
  expect_round_trip(std::vector<std::uint8_t>(640 * 480 * 3, 200), 640, 480);
}

TEST(EncodePng, LargePictureSpansSeveralIdatChunks) {
  const std::vector<std::uint8_t> rgb = random_bytes(700 * 600 * 3, 4);  // 1.26 MB, stored
  const DecodedPng decoded = decode_png(encode_png(rgb, 700, 600));
  EXPECT_EQ(decoded.rgb, rgb);
  EXPECT_GT(std::count(decoded.chunk_types.begin(), decoded.chunk_types.end(), "IDAT"), 1);
}

TEST(EncodePng, RejectsSizeMismatch) {
  const std::vector<std::uint8_t> rgb(10 * 10 * 3);
  EXPECT_THROW(encode_png(rgb, 10, 9), InvalidInputError);
  EXPECT_THROW(encode_png(rgb, 0, 10), InvalidInputError);
  EXPECT_THROW(encode_png({}, 1, 1), InvalidInputError);
}

TEST(WritePng, WritesTheEncodedBytesAtomically) {
  const std::filesystem::path dir = testing::temp_directory("render");
  const std::filesystem::path path = dir / "cube.png";
  RenderOptions options;
  options.width = 64;
  options.height = 48;
  const std::vector<std::uint8_t> rgb = render_mesh(unit_cube(), kCubeSideColors, options);
  write_png(path, rgb, options.width, options.height);
  std::ifstream in(path, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, encode_png(rgb, options.width, options.height));

  // The mesh overload renders the same picture.
  const std::filesystem::path direct = dir / "direct.png";
  write_png(direct, unit_cube(), kCubeSideColors, options);
  EXPECT_EQ(decode_png(encode_png(rgb, options.width, options.height)).rgb,
            decode_png([&] {
              std::ifstream file(direct, std::ios::binary);
              return std::string((std::istreambuf_iterator<char>(file)),
                                 std::istreambuf_iterator<char>());
            }())
                .rgb);

  // Nothing but the two pictures is left in the directory.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            2);
  EXPECT_THROW(write_png(dir / "missing" / "x.png", rgb, options.width, options.height), IoError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace primseg
