#include "cli/command_line.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace airseg::cli {
namespace {

struct Values {
    std::string path;
    unsigned baud = 57600;
    Duration delay{0};
    double loss = 0;
    std::vector<Window> outages;
    bool json = false;
};

OptionTable table_for(Values& v) {
    OptionTable t;
    t.value("path,p", "PATH", "where", text(v.path))
        .value("baud", "N", "serial rate", number(v.baud, 300, 4'000'000))
        .value("delay", "S", "how long", in_seconds(v.delay))
        .value("loss", "P", "lost bytes", probability(v.loss))
        .value("outage", "START:DUR", "no link (repeatable)", windows(v.outages))
        .flag("json", "as JSON", [&v] { v.json = true; })
        .help_and_version();
    return t;
}

std::string error_of(const std::vector<std::string>& args, const Operands& operands = {}) {
    Values v;
    try {
        parse(args, table_for(v), operands);
    } catch (const UsageError& e) {
        return e.what();
    }
    return "";
}

TEST(CommandLine, OptionsActInOrderAndRepeatedOnesApplyAgain) {
    Values v;
    const auto words = parse({"--baud", "9600", "-p", "/dev/a", "--outage", "5:2", "--baud=115200",
                              "--outage", "60:30", "--loss", "0.25", "--delay", "1.5", "--json"},
                             table_for(v));
    EXPECT_TRUE(words.empty());
    EXPECT_EQ(v.baud, 115200u);
    EXPECT_EQ(v.path, "/dev/a");
    ASSERT_EQ(v.outages.size(), 2u);
    EXPECT_EQ(v.outages[1].start, std::chrono::seconds(60));
    EXPECT_EQ(v.loss, 0.25);
    EXPECT_EQ(v.delay, std::chrono::milliseconds(1500));
    EXPECT_TRUE(v.json);
}

TEST(CommandLine, ErrorsNameTheOptionAndTheText) {
    const auto bad_number = error_of({"--baud", "fast"});
    EXPECT_NE(bad_number.find("--baud"), std::string::npos) << bad_number;
    EXPECT_NE(bad_number.find("'fast'"), std::string::npos) << bad_number;
    const auto bad_window = error_of({"--outage", "10"});
    EXPECT_NE(bad_window.find("--outage"), std::string::npos) << bad_window;
    EXPECT_NE(bad_window.find("START:DURATION"), std::string::npos) << bad_window;
    EXPECT_EQ(error_of({"--loss"}), "--loss: missing value");
    EXPECT_EQ(error_of({"stray"}), "unexpected argument 'stray'");
}

TEST(CommandLine, UnknownOptionIsNamedWithTheNearMiss) {
    EXPECT_EQ(error_of({"--jsno"}), "unrecognised option '--jsno' (did you mean '--json'?)");
    // Only unique prefixes with allow_guessing; by default a prefix is unknown.
    EXPECT_NE(error_of({"--bau", "9600"}).find("unrecognised option '--bau'"), std::string::npos);
    EXPECT_EQ(error_of({"--bau", "9600"}, {.allow_guessing = true}), "");
}

TEST(CommandLine, SubcommandOptionsStayInOrderAfterTheFirstWord) {
    Values v;
    const auto words = parse({"--json", "watch", "--duration", "500", "--baud", "9600", "-1.5"}, table_for(v),
                             {.max = 10, .take_unknown_options = true});
    EXPECT_EQ(words, (std::vector<std::string>{"watch", "--duration", "500", "-1.5"}));
    EXPECT_EQ(v.baud, 9600u);
    EXPECT_TRUE(v.json);
    EXPECT_NE(error_of({"--duration", "5", "watch"}, {.max = 10, .take_unknown_options = true})
                  .find("unrecognised option '--duration'"),
              std::string::npos);
}

TEST(CommandLine, RunPrintsHelpVersionAndOneLineErrors) {
    Values v;
    const Program program{"airseg-test", [] { return std::string("usage: airseg-test [options]\n"); }};
    std::ostringstream out;
    std::ostringstream err;
    auto outcome = run(program, {"--help"}, table_for(v), out, err);
    EXPECT_EQ(outcome.exit_code, 0);
    EXPECT_EQ(out.str(), "usage: airseg-test [options]\n");

    // Reading stops at --help: what follows cannot make it an error.
    Values v2;
    out.str("");
    outcome = run(program, {"-h", "--baud", "x"}, table_for(v2), out, err);
    EXPECT_EQ(outcome.exit_code, 0);
    EXPECT_TRUE(err.str().empty());

    Values v3;
    out.str("");
    outcome = run(program, {"--version"}, table_for(v3), out, err);
    EXPECT_EQ(outcome.exit_code, 0);
    EXPECT_EQ(out.str(), std::string("airseg-test ") + AIRSEG_VERSION + "\n");

    Values v4;
    out.str("");
    outcome = run(program, {"--wobble"}, table_for(v4), out, err);
    EXPECT_EQ(outcome.exit_code, kUsageExit);
    EXPECT_TRUE(out.str().empty());
    EXPECT_EQ(err.str(), "airseg-test: unrecognised option '--wobble'; see airseg-test --help\n");

    Values v5;
    outcome = run(program, {"--json"}, table_for(v5), out, err);
    EXPECT_FALSE(outcome.exit_code);
    EXPECT_TRUE(v5.json);
}

TEST(CommandLine, DescribeListsTheOptionsWithTheirValues) {
    Values v;
    const auto text = describe(table_for(v));
    EXPECT_NE(text.find("-p [ --path ] PATH"), std::string::npos) << text;
    EXPECT_NE(text.find("--outage START:DUR"), std::string::npos) << text;
    EXPECT_NE(text.find("--help"), std::string::npos) << text;
}

}  // namespace
}  // namespace airseg::cli
