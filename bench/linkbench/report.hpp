#pragma once
// Presentation of linkbench results: the side-by-side table, the targets, and one JSON object per scenario.
#include <ostream>
#include <string>
#include <vector>

#include "bench/linkbench/scenario.hpp"

namespace airseg::linkbench {

struct Row {
    Scenario scenario;
    ScenarioResult ours;
    ScenarioResult seed;
};

struct TargetCheck {
    std::string name;
    bool evaluated = false;  ///< false when "ours" did not run
    bool pass = false;
    bool seed_pass = false;
    std::string detail;
};

const char* to_string(LinkMode m);

void print_table(std::ostream& os, const std::vector<Row>& rows);
/// Where the bytes went: wire use per direction, air utilisation, FIFO overflow.
void print_diagnostics(std::ostream& os, const std::vector<Row>& rows);
std::vector<TargetCheck> check_targets(const std::vector<Row>& rows);
void print_targets(std::ostream& os, const std::vector<TargetCheck>& checks);
/// One line of JSON per row.
void print_json(std::ostream& os, const std::vector<Row>& rows);

}  // namespace airseg::linkbench
