#pragma once
// Plans written inline in the flight plan tests, loaded as the daemon loads a file.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "services/flightplan/plan_loader.hpp"

namespace airseg::flightplan::test {

/// The plan in `text`; a load error fails the test that called it (and returns null).
inline std::shared_ptr<const Plan> load(const std::string& text) {
    auto r = load_plan_text(text, "test.yaml");
    EXPECT_TRUE(r.ok()) << to_string(r.errors);
    return r.plan;
}

/// A failed load's diagnostics as the user reads them, one per line.
inline std::vector<std::string> messages(const LoadResult& r) {
    std::vector<std::string> out;
    for (const auto& d : r.errors) {
        out.push_back(d.to_string());
    }
    return out;
}

}  // namespace airseg::flightplan::test
