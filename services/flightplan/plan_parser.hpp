#pragma once
// The rules of the plan format (docs/flight-plan.md) applied to a YAML tree: every check and message of the
// loader, with each problem located as file:line:col plus the element path. Either the whole document is
// handed over (run), or the loader's event reader (plan_stream) hands over the parts of a long element list
// one element at a time: begin_plan, then element / begin_container / begin_block ..., then finish. Both ways
// produce the same nodes and the same diagnostics in the same order.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/yaml_tree.hpp"

namespace airseg::flightplan {

/// The longest text field of a plan (names, goto and reaction targets, types): names are shown in every
/// status document and every reply about the plan.
inline constexpr std::size_t kMaxTextBytes = 256;
/// The most vertices of one polygon (a scan's area, a no-fly zone, the geofence).
inline constexpr std::size_t kMaxPolygonVertices = 1000;

class PlanParser {
  public:
    /// Where the items of an element list go: the container, the list's path, and the mapping that holds
    /// the list under "elements".
    struct ListTarget {
        std::uint32_t id = kNoNode;
        std::string path;
        YRef body;
    };

    PlanParser(std::string file, std::size_t max_elements, VehicleProfile vehicle);

    /// The whole document at once.
    LoadResult run(const YRef& doc, const LoadOptions& options);

    // Piecewise, in document order. `doc`/`body` may be mappings still being read: they hold every key that
    // precedes "elements", and the reader guarantees no other key follows it.
    ListTarget begin_plan(const YRef& doc);
    void parse_element(const YRef& item, std::uint32_t parent, const std::string& path);
    /// A repeat or block element whose list follows; nullopt when the element was refused (its list is then
    /// ignored, as parse_element would).
    std::optional<ListTarget> element_head(const YRef& item, std::uint32_t parent, const std::string& path);
    /// A list that turned out empty.
    void empty_list(const YRef& list, std::uint32_t parent, const std::string& path);
    void begin_blocks(const YRef& list);
    void parse_blocks(const YRef& list, const std::string& path);
    void parse_block(const YRef& block, std::size_t index);
    std::optional<ListTarget> block_head(const YRef& block, std::size_t index);
    LoadResult finish(const LoadOptions& options);

  private:
    struct RawScan {
        std::vector<LatLon> polygon;
        double spacing = 0.0;
        double heading = 0.0;
        double step = 0.0;
    };
    struct RawOrbit {
        double radius = 0.0;
        double turns = 1.0;
        bool clockwise = true;
    };

    void error(SourceMark at, const std::string& path, std::string message) {
        errors_.push_back({file_, at.line, at.col, path, std::move(message)});
    }
    void error(const YRef& at, const std::string& path, std::string message);

    bool is_map(const YRef& node, const std::string& path);
    void check_keys(const YRef& map, const std::string& path,
                    std::initializer_list<std::string_view> allowed);
    std::optional<double> number(const YRef& map, const char* key, const std::string& path, bool required,
                                 double lo, double hi, bool lo_open = false);
    std::optional<double> number_value(const YRef& value, const std::string& where, double lo, double hi,
                                       bool lo_open);
    std::optional<std::string> text(const YRef& map, const char* key, const std::string& path, bool required);
    std::optional<LatLon> lat_lon_fields(const YRef& map, const std::string& path, bool required);
    std::optional<LatLon> point(const YRef& node, const std::string& path);
    std::optional<std::vector<LatLon>> polygon(const YRef& node, const std::string& path);
    /// Every position read: the first is the frame's reference unless plan.reference is given; one beyond the
    /// frame's reach (geo.hpp) is an error.
    void note_coordinate(LatLon p, const YRef& at, const std::string& path);

    std::uint32_t add_node(NodeKind kind, std::uint32_t parent, SourceMark mark);
    void set_name(std::uint32_t id, std::optional<std::string> name);
    void set_optional(std::uint32_t id, std::optional<double> NodeExtra::*field, std::optional<double> v);
    void parse_plan(const YRef& plan);
    ListTarget plan_head(const YRef& plan);
    void parse_vehicle(const YRef& vehicle, const std::string& path);
    void parse_reactions(const YRef& reactions, const std::string& path);
    std::optional<Reaction> parse_reaction(const YRef& node, const std::string& path);
    void parse_elements(const YRef& list, std::uint32_t parent, const std::string& path);
    void parse_leaf_common(const YRef& body, std::uint32_t id, const std::string& path);

    void finish_geometry(std::uint64_t max_scan_work);
    void resolve_names();
    void derive_counts(const LoadOptions& options);

    std::string file_;
    std::size_t max_elements_;
    bool too_many_elements_ = false;
    Plan plan_;
    std::vector<Diagnostic> errors_;
    std::optional<LatLon> first_coordinate_;
    std::uint64_t scan_work_ = 0;         // line-edge crossings of the scans laid out so far
    std::uint64_t out_of_frame_ = 0;      // positions beyond the frame's reach
    std::size_t out_of_frame_error_ = 0;  // the error that names the first of them
    std::optional<LatLon> reference_;
    std::map<std::uint32_t, RawScan> scans_;
    std::map<std::uint32_t, RawOrbit> orbits_;
    std::vector<std::pair<std::string, SourceMark>> reaction_paths_;
};

}  // namespace airseg::flightplan
