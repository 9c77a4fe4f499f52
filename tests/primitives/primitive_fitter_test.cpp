// The fitter registry's name parsing, which the CLI, the Python module and the benchmarks share.
#include "primseg/primitives/primitive_fitter.hpp"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "primseg/error.hpp"

namespace primseg {
namespace {

// The message of the InvalidInputError that parsing `text` throws, or "" if none.
template <class Parse>
std::string refusal(Parse parse, std::string_view text) {
  try {
    parse(text);
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return "";
}

constexpr std::string_view kAvailable =
    "(available: 'plane', 'cylinder', 'sphere', 'cone', 'torus')";

TEST(FittableTypes, EveryTypeIsReadByItsOwnName) {
  for (int t = 0; t < kPrimitiveTypeCount; ++t) {
    const auto type = static_cast<PrimitiveType>(t);
    ASSERT_TRUE(has_fitter(type));
    EXPECT_EQ(fittable_type_from_string(to_string(type)), type);
  }
}

TEST(FittableTypes, AnUnknownNameIsRefusedWithTheAvailableOnes) {
  auto parse = [](std::string_view name) { return fittable_type_from_string(name); };
  EXPECT_EQ(refusal(parse, "ellipsoid"),
            "unknown primitive 'ellipsoid' " + std::string(kAvailable));
  EXPECT_EQ(refusal(parse, "Plane"), "unknown primitive 'Plane' " + std::string(kAvailable));
  EXPECT_EQ(refusal(parse, ""), "unknown primitive '' " + std::string(kAvailable));
  EXPECT_EQ(refusal(parse, "unknown"), "unknown primitive 'unknown' " + std::string(kAvailable));
}

TEST(FittableTypes, AListKeepsItsOrderAndItsRepeats) {
  using enum PrimitiveType;
  EXPECT_EQ(fittable_types_from_list("plane"), std::vector<PrimitiveType>{Plane});
  EXPECT_EQ(fittable_types_from_list("torus,plane,sphere"),
            (std::vector<PrimitiveType>{Torus, Plane, Sphere}));
  EXPECT_EQ(fittable_types_from_list("cone,cone"), (std::vector<PrimitiveType>{Cone, Cone}));
}

TEST(FittableTypes, AListWithAnEmptyOrUnknownItemIsRefusedNamingIt) {
  auto parse = [](std::string_view list) { return fittable_types_from_list(list); };
  for (std::string_view list : {"", ",", "plane,", ",plane", "plane,,sphere"})
    EXPECT_EQ(refusal(parse, list), "unknown primitive '' " + std::string(kAvailable)) << list;
  EXPECT_EQ(refusal(parse, "plane,hexagon,sphere"),
            "unknown primitive 'hexagon' " + std::string(kAvailable));
  EXPECT_EQ(refusal(parse, "plane, sphere"),
            "unknown primitive ' sphere' " + std::string(kAvailable));
}

}  // namespace
}  // namespace primseg
