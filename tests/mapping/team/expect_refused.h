#ifndef ROVER_TESTS_MAPPING_TEAM_EXPECT_REFUSED_H_
#define ROVER_TESTS_MAPPING_TEAM_EXPECT_REFUSED_H_

#include <gtest/gtest.h>

#include <string>

#include "mapping/team/team_message.h"

namespace rover::mapping::testing {

/// Expects `f` to throw TeamMessageError mentioning `needle`.
template <typename F>
void ExpectRefused(F f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected a refusal mentioning '" << needle << "'";
  } catch (const TeamMessageError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_TEAM_EXPECT_REFUSED_H_
