#include <gtest/gtest.h>

#include "qsmesh/core/error.hpp"

namespace qsmesh {
namespace {

TEST(Error, CheckThrowsWithMessageAndCondition) {
  const int n = 0;
  try {
    QSMESH_CHECK(n > 0, "face " << 7 << " has no vertex");
    FAIL() << "QSMESH_CHECK did not throw";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("face 7 has no vertex"), std::string::npos) << what;
    EXPECT_NE(what.find("n > 0"), std::string::npos) << what;
  }
}

TEST(Error, CheckPassesSilently) { EXPECT_NO_THROW(QSMESH_CHECK(1 + 1 == 2, "arithmetic")); }

TEST(Error, ContextNamesStageAndEntity) {
  const Error e("no boundary", ErrorContext{"background", 2, 12});
  EXPECT_EQ(std::string(e.what()), "[background] face 12: no boundary");
  const Error inner("bad loop");
  const Error outer = inner.with_context(ErrorContext{"load", 1, 3});
  EXPECT_EQ(std::string(outer.what()), "[load] curve 3: bad loop");
}

}  // namespace
}  // namespace qsmesh
