#include "cli/command_line.hpp"

#include <ostream>
#include <sstream>
#include <utility>

#include "services/common/nearest_word.hpp"

namespace airseg::cli {

namespace {

/// A value semantic that acts at once, in command-line order, instead of storing a typed value for
/// notify(): repeated options then behave as in a hand-written loop (no "multiple occurrences" error).
class Action final : public po::value_semantic {
  public:
    Action(std::string option, std::string value_name, unsigned tokens,
           std::function<void(std::string_view option, std::string_view text)> apply)
        : option_(std::move(option)),
          value_name_(std::move(value_name)),
          tokens_(tokens),
          apply_(std::move(apply)) {}

    std::string name() const override { return value_name_; }
    unsigned min_tokens() const override { return tokens_; }
    unsigned max_tokens() const override { return tokens_; }
    bool is_composing() const override { return false; }
    bool is_required() const override { return false; }
    void parse(boost::any& store, const std::vector<std::string>& tokens, bool) const override {
        apply_(option_, tokens.empty() ? std::string_view() : std::string_view(tokens.front()));
        store = true;
    }
    bool apply_default(boost::any&) const override { return false; }
    void notify(const boost::any&) const override {}

  private:
    std::string option_;
    std::string value_name_;
    unsigned tokens_;
    std::function<void(std::string_view, std::string_view)> apply_;
};

/// The name messages give an option: "--long", or "-s" for an option with only a short name (",s").
std::string display_name(const char* name) {
    const std::string n(name);
    const auto comma = n.find(',');
    return comma == 0 ? "-" + n.substr(1) : "--" + n.substr(0, comma);
}

std::vector<std::string> long_names(const po::options_description& options) {
    std::vector<std::string> names;
    for (const auto& option : options.options()) {
        names.push_back("--" + option->long_name());
    }
    return names;
}

/// Program_options' errors in the words of the programs' own: the option first, then what is wrong.
UsageError reworded(const po::error& e, const po::options_description& options) {
    if (const auto* unknown = dynamic_cast<const po::unknown_option*>(&e)) {
        const auto word = unknown->get_option_name();
        return UsageError("unrecognised option '" + word + "'" +
                          (word.starts_with("--")
                               ? did_you_mean(word.substr(0, word.find('=')), long_names(options))
                               : std::string()));
    }
    if (const auto* syntax = dynamic_cast<const po::invalid_command_line_syntax*>(&e);
        syntax != nullptr && syntax->kind() == po::invalid_command_line_syntax::missing_parameter) {
        return UsageError(syntax->get_option_name() + ": missing value");
    }
    return UsageError(e.what());
}

std::vector<std::string> parse_in_order(const std::vector<std::string>& args,
                                        const po::options_description& options, po::variables_map& values,
                                        const Operands& operands) {
    int style = po::command_line_style::default_style;
    if (!operands.allow_guessing) {
        style &= ~po::command_line_style::allow_guessing;
    }
    try {
        const auto parsed =
            po::command_line_parser(args).options(options).style(style).allow_unregistered().run();
        // The options act first (in order), so that a --help before a bad word still shows the help.
        po::store(parsed, values);
        po::notify(values);
        std::vector<std::string> words;
        for (const auto& o : parsed.options) {
            if (o.unregistered) {
                if (words.empty() || !operands.take_unknown_options) {
                    throw po::unknown_option(o.original_tokens.front());
                }
                words.insert(words.end(), o.original_tokens.begin(), o.original_tokens.end());
            } else if (o.position_key >= 0) {
                words.push_back(o.value.front());
            }
        }
        if (words.size() > operands.max) {
            throw UsageError("unexpected argument '" + words[operands.max] + "'");
        }
        return words;
    } catch (const po::error& e) {
        throw reworded(e, options);
    }
}

}  // namespace

OptionTable::OptionTable(const std::string& caption) : description_(caption) {}

OptionTable& OptionTable::value(const char* name, const char* value_name, const char* help, Apply apply) {
    description_.add_options()(name, new Action(display_name(name), value_name, 1, std::move(apply)), help);
    return *this;
}

OptionTable& OptionTable::flag(const char* name, const char* help, std::function<void()> apply) {
    description_.add_options()(
        name, new Action(display_name(name), "", 0, [apply = std::move(apply)](auto, auto) { apply(); }),
        help);
    return *this;
}

OptionTable& OptionTable::help_and_version(bool with_version) {
    if (with_version) {
        flag("version", "print the version and exit", [v = version_] { *v = true; });
    }
    return flag("help,h", "print this help and exit", [h = help_] { *h = true; });
}

Apply text(std::string& target) {
    return [&target](std::string_view, std::string_view value) { target = value; };
}

Apply in_seconds(Duration& target) {
    return
        [&target](std::string_view option, std::string_view value) { target = parse_seconds(option, value); };
}

Apply in_seconds(std::optional<Duration>& target) {
    return
        [&target](std::string_view option, std::string_view value) { target = parse_seconds(option, value); };
}

Apply in_milliseconds(Duration& target) {
    return [&target](std::string_view option, std::string_view value) {
        target = parse_milliseconds(option, value);
    };
}

Apply probability(double& target) {
    return [&target](std::string_view option, std::string_view value) {
        target = parse_probability(option, value);
    };
}

Apply windows(std::vector<Window>& target) {
    return [&target](std::string_view option, std::string_view value) {
        target.push_back(parse_window(option, value));
    };
}

Apply number(double& target, double min, double max) {
    return [&target, min, max](std::string_view option, std::string_view value) {
        target = parse_double(option, value, min, max);
    };
}

Apply number(float& target, double min, double max) {
    return [&target, min, max](std::string_view option, std::string_view value) {
        target = static_cast<float>(parse_double(option, value, min, max));
    };
}

std::vector<std::string> parse(const std::vector<std::string>& args, const OptionTable& table,
                               const Operands& operands) {
    po::variables_map values;
    try {
        return parse_in_order(args, table.description(), values, operands);
    } catch (const UsageError&) {
        if (table.help_requested()) {
            return {};  // reading stops at --help, as the help says what is wrong after it
        }
        throw;
    }
}

std::vector<std::string> parse(const std::vector<std::string>& args, const po::options_description& options,
                               po::variables_map& values, const Operands& operands) {
    return parse_in_order(args, options, values, operands);
}

int usage_error(std::ostream& err, std::string_view program, std::string_view message) {
    err << program << ": " << message << "; see " << program << " --help\n";
    return kUsageExit;
}

Outcome run(const Program& program, const std::vector<std::string>& args, const OptionTable& table,
            std::ostream& out, std::ostream& err, const Operands& operands) {
    Outcome outcome;
    try {
        outcome.operands = parse(args, table, operands);
    } catch (const UsageError& e) {
        outcome.exit_code = usage_error(err, program.name, e.what());
        return outcome;
    }
    if (table.help_requested()) {
        out << program.help();
        outcome.exit_code = 0;
    } else if (table.version_requested()) {
        out << program.name << ' ' << AIRSEG_VERSION << '\n';
        outcome.exit_code = 0;
    }
    return outcome;
}

std::string describe(const OptionTable& table) {
    std::ostringstream out;
    out << table.description();
    return out.str();
}

}  // namespace airseg::cli
