// detail::parse_length: the one parser of "T" and "T%" lengths the CLI (--tolerance,
// --relation-length-tolerance) and the Python module (relation_length_tolerance="T%") share.
#include "length_text.hpp"

#include <gtest/gtest.h>

#include <string>

#include "primseg/error.hpp"

namespace primseg {
namespace {

using detail::is_percentage;
using detail::length_syntax_error;
using detail::parse_length;

TEST(LengthText, ALengthIsInInputUnitsAndAPercentageOfTheDiagonal) {
  EXPECT_EQ(parse_length("0.25", 7, "--x"), 0.25);
  EXPECT_EQ(parse_length("0", 7, "--x"), 0);
  // T / 100 × the diagonal, in that order: every interface gets the same double.
  EXPECT_EQ(parse_length("0.0014%", 1.4521458501128597, "--x"), 0.0014 / 100 * 1.4521458501128597);
  EXPECT_TRUE(is_percentage("2%"));
  EXPECT_FALSE(is_percentage("2"));
  EXPECT_FALSE(is_percentage(""));
}

TEST(LengthText, AnythingElseIsRefusedNamingTheOption) {
  for (const std::string bad : {"", "%", "-1", "-1%", "inf", "nan%", "1e-3 %", " 1", "1x", "%1"}) {
    EXPECT_FALSE(length_syntax_error(bad).empty()) << bad;
    try {
      parse_length(bad, 1, "--relation-length-tolerance");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InvalidInputError& error) {
      EXPECT_EQ(std::string(error.what()).rfind("--relation-length-tolerance: '" + bad + "'", 0),
                0u)
          << error.what();
    }
  }
  EXPECT_TRUE(length_syntax_error("1e-3%").empty());
}

}  // namespace
}  // namespace primseg
