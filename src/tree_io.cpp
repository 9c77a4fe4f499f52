#include "primseg/tree_io.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include "file_io.hpp"
#include "huge_pages.hpp"
#include "primseg/error.hpp"

namespace primseg {
namespace {

constexpr char kMagic[8] = {'P', 'R', 'I', 'M', 'S', 'E', 'G', 'T'};
constexpr std::uint32_t kVersion = 1;
// A merge's bytes: 12 doubles, 3 uint32 and 2 bytes (docs/tree-format.md).
constexpr std::size_t kMergeBytes = 110;

std::uint64_t fnv1a(std::string_view bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (unsigned char c : bytes) hash = (hash ^ c) * 0x100000001b3ull;
  return hash;
}

class Writer {
 public:
  template <typename T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>);
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
    bytes_.append(raw, sizeof(T));
  }
  void put_vec3(const Vec3& v) {
    for (double x : v) put(x);
  }
  void put_raw(const char* data, std::size_t n) { bytes_.append(data, n); }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  Reader(std::span<const char> bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  template <typename T>
  T get(const char* what) {
    need(sizeof(T), what);
    char raw[sizeof(T)];
    std::memcpy(raw, bytes_.data() + offset_, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
    offset_ += sizeof(T);
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }
  // A byte that must be 0 or 1.
  bool get_flag(const char* field, const char* what) {
    const auto value = get<std::uint8_t>(what);
    if (value > 1) fail(std::string(field) + " must be 0 or 1, not " + std::to_string(value));
    return value == 1;
  }
  Vec3 get_vec3(const char* what) {
    return {get<double>(what), get<double>(what), get<double>(what)};
  }
  // A count of items of `item_size` bytes each, checked against the bytes left.
  std::size_t get_count(std::size_t item_size, const char* what) {
    const auto count = get<std::uint64_t>(what);
    if (count > (bytes_.size() - offset_) / item_size)
      fail(std::string(what) + " count " + std::to_string(count) + " exceeds the file size");
    return static_cast<std::size_t>(count);
  }
  void need(std::size_t n, const char* what) {
    if (bytes_.size() - offset_ < n) fail(std::string("truncated file while reading ") + what);
  }
  [[noreturn]] void fail(const std::string& reason) const {
    throw ParseError(name_ + ": byte " + std::to_string(offset_) + ": " + reason);
  }
  std::size_t offset() const { return offset_; }

 private:
  std::span<const char> bytes_;
  std::string name_;
  std::size_t offset_ = 0;
};

// The first checks of every reader: the magic number, as far as `bytes` holds it (`r` at their
// start), then, from `r`, the magic number and a version this primseg reads.
void check_magic(std::span<const char> bytes, const Reader& r) {
  const std::size_t length = std::min(bytes.size(), sizeof kMagic);
  if (length > 0 && std::memcmp(bytes.data(), kMagic, length) != 0)
    r.fail("not a primseg tree file (bad magic number)");
}

void read_magic_and_version(Reader& r) {
  for (std::size_t i = 0; i < sizeof kMagic; ++i) r.get<char>("the header");
  const auto version = r.get<std::uint32_t>("the version");
  if (version != kVersion)
    r.fail("tree file version " + std::to_string(version) +
           " is not supported (this primseg reads version " + std::to_string(kVersion) + ")");
}

}  // namespace

std::string serialize_tree(const Hierarchy& hierarchy) {
  Writer w;
  const Mesh& mesh = hierarchy.mesh();
  // The header and counts take a few hundred bytes, the arrays their items' sizes; in huge pages
  // (a million-face tree takes about 200 MB).
  detail::reserve_huge(w.bytes(),
                       1024 + 24 * mesh.positions.size() + 4 * mesh.polygon_offsets.size() +
                           4 * mesh.polygon_vertices.size() + 16 * mesh.triangles.size() +
                           kMergeBytes * hierarchy.merges().size());
  w.put_raw(kMagic, sizeof kMagic);
  w.put(kVersion);
  const HierarchyOptions& options = hierarchy.options();
  w.put(static_cast<std::uint8_t>(options.weights));
  w.put(static_cast<std::uint8_t>(options.exact_costs));
  w.put(static_cast<std::uint8_t>(options.primitives.size()));
  for (PrimitiveType t : options.primitives) w.put(static_cast<std::uint8_t>(t));
  for (double p : options.type_penalty) w.put(p);
  w.put(options.zero_cost_tolerance);

  w.put(static_cast<std::uint64_t>(mesh.positions.size()));
  for (const Vec3& p : mesh.positions) w.put_vec3(p);
  w.put(static_cast<std::uint64_t>(mesh.polygon_offsets.size()));
  for (std::uint32_t o : mesh.polygon_offsets) w.put(o);
  w.put(static_cast<std::uint64_t>(mesh.polygon_vertices.size()));
  for (std::uint32_t v : mesh.polygon_vertices) w.put(v);
  w.put(static_cast<std::uint64_t>(mesh.triangles.size()));
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (std::uint32_t v : mesh.triangles[t]) w.put(v);
    w.put(mesh.face_of_triangle[t]);
  }

  w.put(static_cast<std::uint64_t>(hierarchy.merges().size()));
  for (const Merge& m : hierarchy.merges()) {
    w.put(m.first);
    w.put(m.second);
    w.put(m.cost);
    w.put(m.error);
    w.put(m.weight);
    w.put(m.face_count);
    w.put(static_cast<std::uint8_t>(m.trailing));
    w.put(static_cast<std::uint8_t>(m.primitive.type));
    w.put_vec3(m.primitive.point);
    w.put_vec3(m.primitive.axis);
    w.put(m.primitive.radius);
    w.put(m.primitive.minor_radius);
    w.put(m.primitive.half_angle);
  }
  w.put(fnv1a(w.bytes()));
  return std::move(w.bytes());
}

Hierarchy deserialize_tree(std::span<const char> bytes, const std::string& name) {
  if (bytes.empty()) throw ParseError(name + ": empty file");
  Reader r(bytes, name);
  r.need(sizeof kMagic, "the header");
  check_magic(bytes, r);
  if (bytes.size() < sizeof kMagic + 4 + 8) r.fail("truncated file while reading the header");
  {
    Reader checksum_reader(bytes.subspan(bytes.size() - 8), name);
    const auto stored = checksum_reader.get<std::uint64_t>("the checksum");
    if (stored != fnv1a({bytes.data(), bytes.size() - 8}))
      throw ParseError(name + ": checksum mismatch: the file is corrupt or truncated");
  }
  bytes = bytes.first(bytes.size() - 8);
  r = Reader(bytes, name);
  read_magic_and_version(r);

  HierarchyOptions options;
  const auto weights = r.get<std::uint8_t>("the options");
  if (weights > 1) r.fail("unknown vertex weighting " + std::to_string(weights));
  options.weights = static_cast<VertexWeights>(weights);
  options.exact_costs = r.get_flag("exact_costs", "the options");
  const auto type_count = r.get<std::uint8_t>("the options");
  options.primitives.clear();
  for (int i = 0; i < type_count; ++i) {
    const auto t = r.get<std::uint8_t>("the primitive types");
    if (t >= kPrimitiveTypeCount) r.fail("unknown primitive type " + std::to_string(t));
    options.primitives.push_back(static_cast<PrimitiveType>(t));
  }
  for (double& p : options.type_penalty) p = r.get<double>("the type penalties");
  options.zero_cost_tolerance = r.get<double>("the options");

  auto mesh = std::make_shared<Mesh>();
  // The arrays in huge pages, as read_mesh's (a million faces fill about 200 MB here).
  detail::resize_huge(mesh->positions, r.get_count(24, "vertex"));
  for (Vec3& p : mesh->positions) p = r.get_vec3("the vertices");
  std::vector<std::uint32_t> offsets;  // fresh, not the default {0} resized (see from_triangles)
  detail::resize_huge(offsets, r.get_count(4, "polygon offset"));
  for (std::uint32_t& o : offsets) o = r.get<std::uint32_t>("the polygons");
  mesh->polygon_offsets = std::move(offsets);
  detail::resize_huge(mesh->polygon_vertices, r.get_count(4, "polygon vertex"));
  for (std::uint32_t& v : mesh->polygon_vertices) v = r.get<std::uint32_t>("the polygons");
  const std::size_t triangle_count = r.get_count(16, "triangle");
  detail::resize_huge(mesh->triangles, triangle_count);
  detail::resize_huge(mesh->face_of_triangle, triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    for (std::uint32_t& v : mesh->triangles[t]) v = r.get<std::uint32_t>("the triangles");
    mesh->face_of_triangle[t] = r.get<std::uint32_t>("the triangles");
  }
  try {
    mesh->validate();
    check_geometric_range(*mesh);
  } catch (const Error& e) {
    r.fail(std::string("invalid mesh: ") + e.what());
  }

  std::vector<Merge> merges;
  detail::resize_huge(merges, r.get_count(kMergeBytes, "merge"));
  for (Merge& m : merges) {
    m.first = r.get<std::uint32_t>("the merges");
    m.second = r.get<std::uint32_t>("the merges");
    m.cost = r.get<double>("the merges");
    m.error = r.get<double>("the merges");
    m.weight = r.get<double>("the merges");
    m.face_count = r.get<std::uint32_t>("the merges");
    m.trailing = r.get_flag("a merge's trailing flag", "the merges");
    const auto type = r.get<std::uint8_t>("the merges");
    if (type >= kPrimitiveTypeCount) r.fail("unknown primitive type " + std::to_string(type));
    m.primitive.type = static_cast<PrimitiveType>(type);
    m.primitive.point = r.get_vec3("the merges");
    m.primitive.axis = r.get_vec3("the merges");
    m.primitive.radius = r.get<double>("the merges");
    m.primitive.minor_radius = r.get<double>("the merges");
    m.primitive.half_angle = r.get<double>("the merges");
  }
  if (r.offset() != bytes.size()) r.fail("unexpected data after the merges");
  try {
    return Hierarchy(std::move(mesh), std::move(options), std::move(merges));
  } catch (const InvalidInputError& e) {
    throw ParseError(name + ": invalid tree: " + e.what());
  }
}

TreeSizeBound tree_size_from_prefix(std::span<const char> prefix, const std::string& name) {
  Reader r(prefix, name);
  check_magic(prefix, r);
  constexpr std::uint64_t kMost = std::numeric_limits<std::uint64_t>::max();
  const auto plus = [](std::uint64_t a, std::uint64_t b) { return a > kMost - b ? kMost : a + b; };
  const auto times = [](std::uint64_t count, std::uint64_t size) {
    return count > kMost / size ? kMost : count * size;
  };
  // The layout of docs/tree-format.md: a fixed header, the primitive types, then four counted
  // arrays and the merges, and the checksum. Fields not yet in the prefix end the walk.
  constexpr std::uint64_t kHeader = sizeof kMagic + 4 + 3;  // magic, version, 3 option bytes
  constexpr std::uint64_t kPenalties = std::uint64_t{5} * 8, kTolerance = 8, kCount = 8;
  constexpr std::uint64_t kChecksum = 8;
  // So far: no primitive type, and only the first count of empty arrays.
  std::uint64_t bytes = kHeader + kPenalties + kTolerance + kCount + kChecksum;
  if (prefix.size() < kHeader) return {bytes, false};
  read_magic_and_version(r);
  r.get<std::uint8_t>("the options");
  r.get<std::uint8_t>("the options");
  const auto type_count = r.get<std::uint8_t>("the options");
  bytes += type_count;
  // Where each count lies, and the size of the items it counts.
  std::uint64_t at = kHeader + type_count + kPenalties + kTolerance;
  const std::uint64_t item_sizes[] = {24, 4, 4, 16, kMergeBytes};
  for (std::size_t k = 0; k < std::size(item_sizes); ++k) {
    if (at > prefix.size() || prefix.size() - at < kCount) return {bytes, false};
    const std::uint64_t count =
        Reader(prefix.subspan(at, kCount), name).get<std::uint64_t>("a count");
    const std::uint64_t array = times(count, item_sizes[k]);
    bytes = plus(bytes, array);
    at = plus(at, plus(kCount, array));
    if (k + 1 < std::size(item_sizes)) bytes = plus(bytes, kCount);  // the next count
  }
  return {bytes, true};
}

void write_tree(const std::filesystem::path& path, const Hierarchy& hierarchy) {
  detail::write_file_atomically(path, serialize_tree(hierarchy));
}

Hierarchy read_tree(const std::filesystem::path& path) {
  const detail::FileImage file = detail::read_file(path);
  return deserialize_tree({file.bytes.get(), file.size}, path.string());
}

}  // namespace primseg
