#pragma once
// What every airseg program's command line needs once, on Boost.Program_options: options that act in
// command-line order, --help and --version, and one line per bad command line (exit code 2).
#include <boost/program_options.hpp>

#include <concepts>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli/values.hpp"

namespace airseg::cli {

namespace po = boost::program_options;

/// Exit code of a bad command line, the same for every program.
inline constexpr int kUsageExit = 2;

/// Stores one option's text or throws UsageError; option is the name as given ("--baud").
using Apply = std::function<void(std::string_view option, std::string_view text)>;

/// An option table whose entries act in command-line order, as hand-written loops do: a repeated option
/// applies again (the last value wins, or it appends), and an option may build on an earlier one.
class OptionTable {
  public:
    explicit OptionTable(const std::string& caption = {});

    /// NAME ("long" or "long,s") with one value, e.g. value("baud", "N", "serial rate", number(o.baud, 300,
    /// 4e6)).
    OptionTable& value(const char* name, const char* value_name, const char* help, Apply apply);
    /// NAME without a value.
    OptionTable& flag(const char* name, const char* help, std::function<void()> apply);
    /// --help (-h) and, when with_version, --version; see help_requested() and version_requested().
    OptionTable& help_and_version(bool with_version = true);

    bool help_requested() const { return *help_; }
    bool version_requested() const { return *version_; }

    const po::options_description& description() const { return description_; }

  private:
    po::options_description description_;
    // Shared with the actions, which outlive a move of the table.
    std::shared_ptr<bool> help_ = std::make_shared<bool>(false);
    std::shared_ptr<bool> version_ = std::make_shared<bool>(false);
};

// Option values: each returns the Apply that parses the text into target (see cli/values.hpp).
Apply text(std::string& target);
Apply in_seconds(Duration& target);
Apply in_seconds(std::optional<Duration>& target);
Apply in_milliseconds(Duration& target);
Apply probability(double& target);
Apply windows(std::vector<Window>& target);  ///< repeatable "START:DURATION"
Apply number(double& target, double min, double max);
Apply number(float& target, double min, double max);
template <std::unsigned_integral T>
Apply number(T& target, std::uint64_t min, std::uint64_t max) {
    return [&target, min, max](std::string_view option, std::string_view value) {
        target = static_cast<T>(parse_unsigned(option, value, min, max));
    };
}

/// How parse() treats words that are not options.
struct Operands {
    std::size_t max = 0;  ///< how many positional words are allowed
    /// Unknown options after the first positional word belong to it (a subcommand's own options) and are
    /// kept in order among the operands; before it they are errors.
    bool take_unknown_options = false;
    /// Also accept unique prefixes of long option names ("--conf" for "--config").
    bool allow_guessing = false;
};

/// Parses args (without the program name) against the table: the options act in order, then the
/// positional words (and subcommand options) are returned in order. Throws UsageError with one line that
/// names the option and the bad text.
std::vector<std::string> parse(const std::vector<std::string>& args, const OptionTable& table,
                               const Operands& operands = {});

/// The same for a table of plain Program_options values: they end up in values.
std::vector<std::string> parse(const std::vector<std::string>& args, const po::options_description& options,
                               po::variables_map& values, const Operands& operands = {});

/// One program's command line from main()'s view.
struct Program {
    std::string name;                   ///< starts every message, e.g. "airseg-linksim"
    std::function<std::string()> help;  ///< the --help text
};

/// Prints "NAME: message; see NAME --help" and returns kUsageExit.
int usage_error(std::ostream& err, std::string_view program, std::string_view message);

/// Parses for main(): the operands, or the exit code after printing the help (0), the version (0) or the
/// reason the command line is bad (kUsageExit). --help wins over errors after it, as it stops reading.
struct Outcome {
    std::optional<int> exit_code;
    std::vector<std::string> operands;
};
Outcome run(const Program& program, const std::vector<std::string>& args, const OptionTable& table,
            std::ostream& out, std::ostream& err, const Operands& operands = {});

/// --help's options block: the table as Program_options formats it.
std::string describe(const OptionTable& table);

}  // namespace airseg::cli
