#include "services/flightplan/plan_loader.hpp"

#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>

#include <fstream>
#include <istream>
#include <memory>
#include <streambuf>

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

/// `open` gives the text from its start, once per reading: streamed first, whole if the layout needs it.
template <typename Open>
LoadResult load_from(Open open, const std::string& source_name, const LoadOptions& options) {
    for (const bool stream : {true, false}) {
        PlanParser parser(source_name, options.max_elements, options.default_vehicle);
        PlanEventReader reader(parser, options, stream);
        try {
            auto in = open();
            YAML::Parser yaml(*in);
            yaml.HandleNextDocument(reader);
            return reader.result();
        } catch (const NotStreamable&) {
            continue;
        } catch (const YAML::ParserException& e) {
            return one_error(source_name, e.mark.line + 1, e.mark.column + 1, "YAML syntax error: " + e.msg);
        } catch (const YAML::Exception& e) {
            // yaml-cpp throws for shapes our checks did not anticipate; still a located, clean rejection.
            return one_error(source_name, e.mark.line + 1, e.mark.column + 1, "malformed plan: " + e.msg);
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
                     source_name, options);
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
    // The file is read as it is parsed, never held whole.
    return load_from(
        [&]() -> std::unique_ptr<std::istream> {
            return std::make_unique<std::ifstream>(path, std::ios::binary);
        },
        path, options);
}

}  // namespace airseg::flightplan
