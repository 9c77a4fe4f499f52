// Writes the stick figure of the skeleton tests (support/stick_figure.hpp) to a mesh file, for the
// tests that are not in C++: the viewer's browser tests pose it in the page and with
// `primseg deform`.
//
// Usage: primseg_write_stick_figure OUTPUT.off [EDGE]

#include <cstdio>
#include <exception>
#include <string>

#include "primseg/mesh_io.hpp"
#include "support/stick_figure.hpp"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s OUTPUT.off [EDGE]\n", argv[0]);
    return 2;
  }
  try {
    const double edge = argc == 3 ? std::stod(argv[2]) : 0.12;
    primseg::write_mesh(argv[1], primseg::testing::make_stick_figure(edge).mesh);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
  return 0;
}
