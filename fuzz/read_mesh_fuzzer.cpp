// libFuzzer target for one mesh reader: built once per format (PRIMSEG_FUZZ_FORMAT is Off, Obj,
// Ply or Stl) and once for the content-detecting loader (PRIMSEG_FUZZ_DETECT).
//
// Any input must either give a mesh that satisfies Mesh's invariants or throw primseg::Error:
// a crash, a sanitizer report, another exception, a hang or an allocation beyond libFuzzer's
// -rss_limit_mb is a finding.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
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
  } catch (const primseg::Error&) {
    // A clear rejection is the expected outcome for most inputs.
  }
  return 0;
}
