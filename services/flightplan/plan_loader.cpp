#include "services/flightplan/plan_loader.hpp"

#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>

#include <fstream>
#include <istream>
#include <memory>
#include <streambuf>

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

LoadResult load_plan_text(std::string_view text, const std::string& source_name, const LoadOptions& options) {
    if (text.size() > kMaxPlanTextBytes) {
        return one_error(source_name, 0, 0,
                         "plan larger than " + std::to_string(kMaxPlanTextBytes) + " bytes");
    }
    return load_from([&]() -> std::unique_ptr<std::istream> { return std::make_unique<TextStream>(text); },
                     text, source_name, options);
}

LoadResult load_plan_file(const std::string& path, const LoadOptions& options) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        return one_error(path, 0, 0, "cannot open the file");
    }
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) {
        // Not seekable (a pipe): read it into memory, as much as a plan may be.
        in.clear();
        std::ifstream again(path, std::ios::binary);
        std::string text(kMaxPlanTextBytes + 1, '\0');
        again.read(text.data(), static_cast<std::streamsize>(text.size()));
        text.resize(static_cast<std::size_t>(again.gcount()));
        text.shrink_to_fit();
        return load_plan_text(text, path, options);
    }
    if (static_cast<std::uint64_t>(size) > kMaxPlanTextBytes) {
        return one_error(path, 0, 0, "plan larger than " + std::to_string(kMaxPlanTextBytes) + " bytes");
    }
    // The file is read as it is parsed, never held whole; its main list is then not spliced (load_from).
    return load_from(
        [&]() -> std::unique_ptr<std::istream> {
            return std::make_unique<std::ifstream>(path, std::ios::binary);
        },
        std::string_view(), path, options);
}

}  // namespace airseg::flightplan
