#include "services/flightplan/plan_loader.hpp"

#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>

#include <istream>
#include <memory>
#include <streambuf>

#include "base/file_text.hpp"
#include "base/utf8.hpp"
#include "services/flightplan/list_splice.hpp"
#include "services/flightplan/plan_parser.hpp"
#include "services/flightplan/plan_stream.hpp"
#include "services/flightplan/text_stream.hpp"

namespace airseg::flightplan {

namespace {

LoadResult one_error(const std::string& source, int line, int col, std::string message) {
    LoadResult r;
    r.errors.push_back({source, line, col, "", std::move(message)});
    return r;
}

/// `open` gives the text from its start, once per reading. `text` is the whole text when it is in memory
/// (the main list can then be spliced out), else empty.
template <typename Open>
LoadResult load_from(Open open, std::string_view text, const std::string& source_name,
                     const LoadOptions& options) {
    const auto splice = text.empty() ? std::nullopt : find_list_splice(text, options.splice_batch_items);
    for (const PlanReading reading : {PlanReading::Spliced, PlanReading::Streamed, PlanReading::Whole}) {
        if (reading == PlanReading::Spliced && !splice) {
            continue;
        }
        PlanParser parser(source_name, options.max_elements, options.default_vehicle);
        PlanEventReader reader(parser, options, reading != PlanReading::Whole);
        try {
            if (reading == PlanReading::Spliced) {
                reader.splice(text, *splice);
                SplicedBuffer buffer(text, *splice);
                std::istream in(&buffer);
                YAML::Parser yaml(in);
                yaml.HandleNextDocument(reader);
            } else {
                auto in = open();
                YAML::Parser yaml(*in);
                yaml.HandleNextDocument(reader);
            }
            LoadResult result = reader.result();
            result.reading = reading;
            return result;
        } catch (const NotStreamable&) {
            continue;
        } catch (const YAML::Exception& e) {
            if (reading == PlanReading::Spliced) {
                continue;  // the unspliced reading finds the error, and where it is, on its own
            }
            // yaml-cpp throws for shapes our checks did not anticipate; still a located, clean rejection.
            const bool syntax = dynamic_cast<const YAML::ParserException*>(&e) != nullptr;
            LoadResult result = one_error(source_name, e.mark.line + 1, e.mark.column + 1,
                                          (syntax ? "YAML syntax error: " : "malformed plan: ") + e.msg);
            result.reading = reading;
            return result;
        }
    }
    return one_error(source_name, 0, 0, "malformed plan");
}

}  // namespace

namespace {

/// A text yaml-cpp would misread, refused at the edge with its place: malformed bytes would reach the plan's
/// names (and make every JSON document that shows them throw), a NUL would silently end the plan.
std::optional<Diagnostic> text_problem(std::string_view text, const std::string& source_name) {
    const auto fault = first_text_fault(text);
    if (!fault) {
        return std::nullopt;
    }
    const auto where = position_of(text, fault->offset);
    return Diagnostic{source_name, static_cast<int>(where.line), static_cast<int>(where.column), "",
                      fault->what() + ": a plan is UTF-8 text without control characters"};
}

}  // namespace

LoadResult load_plan_text(std::string_view text, const std::string& source_name, const LoadOptions& options) {
    if (text.size() > kMaxPlanTextBytes) {
        return one_error(source_name, 0, 0,
                         "plan larger than the " + size_text(kMaxPlanTextBytes) + " allowed (" +
                             std::to_string(text.size()) + " bytes)");
    }
    if (auto problem = text_problem(text, source_name)) {
        LoadResult r;
        r.errors.push_back(std::move(*problem));
        return r;
    }
    return load_from([&]() -> std::unique_ptr<std::istream> { return std::make_unique<TextStream>(text); },
                     text, source_name, options);
}

LoadResult load_plan_file(const std::string& path, const LoadOptions& options) {
    // Only a regular file up to the cap: a FIFO, a directory or /dev/zero is refused at once.
    const RegularFile file = RegularFile::open(path, kMaxPlanTextBytes);
    if (!file.ok()) {
        return one_error(path, 0, 0, file.error());
    }
    // The file is read as it is parsed, never held whole; its main list is then not spliced (load_from). Its
    // texts are checked as they are read (PlanEventReader).
    bool grew = false;
    auto result =
        load_from([&]() -> std::unique_ptr<std::istream> { return std::make_unique<FileStream>(file, grew); },
                  std::string_view(), path, options);
    if (grew) {
        return one_error(
            path, 0, 0,
            "larger than the " + size_text(kMaxPlanTextBytes) + " allowed (it grew while it was read)");
    }
    return result;
}

}  // namespace airseg::flightplan
