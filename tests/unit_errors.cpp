// The program's own invariant checks (base/errors.hpp): FDEM_VERIFY throws InternalError naming
// the source file:line, the failed condition and the message, and does nothing when the
// condition holds (the condition is evaluated once); FDEM_ASSERT is the same in a debug build and
// evaluates nothing under NDEBUG. Used where a bug, not input, would break an invariant: the
// particle count across migration (app/engine.cpp), the FE partition against the mesh and the
// rank count (fem/fe_model.cpp), a tied node's target in a snapshot (app/fe_driver.cpp).
#include <gtest/gtest.h>

#include <string>

#include "base/errors.hpp"

namespace {

int verify_twice(int& calls) {
  FDEM_VERIFY(++calls > 0, "never");
  FDEM_VERIFY(calls == 1, "the condition was evaluated " + std::to_string(calls) + " times");
  return calls;
}

}  // namespace

TEST(Errors, VerifyPassesAndEvaluatesOnce) {
  int calls = 0;
  EXPECT_EQ(verify_twice(calls), 1);
}

TEST(Errors, VerifyThrowsWithFileLineConditionAndMessage) {
  const int line = __LINE__ + 2;
  try {
    FDEM_VERIFY(1 + 1 == 3, "arithmetic broke: " + std::to_string(2));
    FAIL() << "FDEM_VERIFY did not throw";
  } catch (const fdem::InternalError& e) {
    const std::string w = e.what();
    EXPECT_EQ(e.line(), line);
    EXPECT_NE(std::string(e.file()).find("unit_errors.cpp"), std::string::npos) << w;
    EXPECT_NE(w.find("unit_errors.cpp:" + std::to_string(line) + ": internal error: arithmetic broke: 2"), std::string::npos) << w;
    EXPECT_NE(w.find("(1 + 1 == 3 is false)"), std::string::npos) << w;
  }
  // an InternalError is a std::logic_error, not an input error: the command line reports it as a bug
  EXPECT_THROW(FDEM_VERIFY(false, "x"), std::logic_error);
}

TEST(Errors, AssertIsVerifyInDebugAndNothingInRelease) {
  int calls = 0;
#ifdef NDEBUG
  FDEM_ASSERT(++calls < 0, "not evaluated under NDEBUG");
  EXPECT_EQ(calls, 0);
#else
  EXPECT_THROW(FDEM_ASSERT(++calls < 0, "evaluated in a debug build"), fdem::InternalError);
  EXPECT_EQ(calls, 1);
#endif
}
