// libFuzzer target for one mesh reader: built once per format (PRIMSEG_FUZZ_FORMAT is Off, Obj,
// Ply or Stl) and once for the content-detecting loader (PRIMSEG_FUZZ_DETECT).
//
// Any input must either give a mesh that satisfies Mesh's invariants or throw primseg::Error:
// a crash, a sanitizer report, another exception, a hang or an allocation beyond libFuzzer's
// -rss_limit_mb is a finding. The detecting target also checks what mesh_format_ruled_out()
// promises to a reader of a stream.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <string_view>

#include "primseg/error.hpp"
#include "primseg/mesh_info.hpp"
#include "primseg/mesh_io.hpp"

#ifdef PRIMSEG_FUZZ_DETECT
namespace {

// mesh_format_ruled_out() claims that no data starting with a ruled-out prefix, up to its
// max_size, is detected as a mesh. Checked on the input padded to the 64 KiB the text signatures
// are read from, then followed by nothing or by the input again. The padding, "x x x ...", is
// copied from one string made once: padding with zeros made each input's first token 64 KiB long,
// and reading it (instrumented) made this target 8 times slower (105k executions in 20 s against
// 800k; 590k like this).
void check_ruled_out_prefix(std::span<const char> bytes) {
  static const std::string padding = [] {
    std::string text;
    for (std::size_t i = 0; i < primseg::kMeshSignatureBytes / 2; ++i) text += "x ";
    return text;
  }();
  static std::string data;
  data.assign(bytes.begin(), bytes.end());
  if (data.size() < primseg::kMeshSignatureBytes)
    data.append(padding, 0, primseg::kMeshSignatureBytes - data.size());
  const std::size_t prefix = data.size();
  if (!primseg::mesh_format_ruled_out(data, prefix + bytes.size())) return;
  for (const bool continued : {false, true}) {
    if (continued) data.append(bytes.begin(), bytes.end());
    if (primseg::detect_mesh_format(data)) {
      std::fprintf(stderr, "a ruled-out prefix of %zu bytes was detected as a mesh with %zu more\n",
                   prefix, data.size() - prefix);
      std::abort();
    }
  }
}

}  // namespace
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
#ifdef PRIMSEG_FUZZ_DETECT
  check_ruled_out_prefix(bytes);
#endif
  try {
#ifdef PRIMSEG_FUZZ_DETECT
    const primseg::Mesh mesh = primseg::read_mesh_detecting_format(bytes, "fuzz");
#else
    const primseg::Mesh mesh =
        primseg::read_mesh(bytes, primseg::MeshFormat::PRIMSEG_FUZZ_FORMAT, "fuzz");
#endif
    try {
      mesh.validate();
    } catch (const primseg::Error& e) {
      // A reader returned a mesh that breaks the invariants the engine relies on.
      std::fprintf(stderr, "reader returned an invalid mesh: %s\n", e.what());
      std::abort();
    }
    if (mesh.face_count() == 0) {
      std::fprintf(stderr, "reader returned a mesh without faces\n");
      std::abort();
    }
    // `primseg info` describes whatever a reader returns, coordinates of any finite size too.
    const primseg::MeshInfo info = primseg::describe_mesh(mesh);
    if (info.triangles != mesh.triangle_count() || info.components == 0 ||
        info.components > info.faces || info.inward_components > info.components ||
        info.inconsistent_edges > 3 * std::size_t{info.triangles} / 2) {
      std::fprintf(stderr, "info: inconsistent counts\n");
      std::abort();
    }
  } catch (const primseg::Error&) {
    // A clear rejection is the expected outcome for most inputs.
  }
  return 0;
}
