#pragma once
// Plans written inline in the flight plan tests, loaded as the daemon loads a file.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "services/flightplan/plan_loader.hpp"

namespace airseg::flightplan::test {

/// The plan in `text`; a load error fails the test that called it (and returns null).
inline std::shared_ptr<const Plan> load(const std::string& text) {
    auto r = load_plan_text(text, "test.yaml");
    EXPECT_TRUE(r.ok()) << to_string(r.errors);
    return r.plan;
}

}  // namespace airseg::flightplan::test
