#pragma once
// Reads a plan from yaml-cpp's parser events without holding the document: the items of the plan's element
// lists (the main list, repeat/block bodies reached through it, the named blocks) are built one at a time,
// handed to the PlanParser and dropped, so a long explicit list costs its plan nodes, not a YAML tree.
//
// The parser's checks run in a fixed order (the plan's fields before its elements, a container's fields
// before its children). A list is therefore only streamed when the document is laid out in that order: no
// other key after a streamed "elements" (but "blocks" after the plan's), one key per element, no anchor on
// what holds the list. When a document breaks that promise after streaming began, reading stops with
// NotStreamable and the loader reads it again as a whole tree (stream = false): same result, more memory.
//
// With a ListSplice, the parser reads the text with the plan's main list cut out (list_splice.hpp); the
// reader reads the list's batches itself where the stand-in list starts, and gives every mark as a place in
// the original text. A document that does not meet the splice where expected stops with NotStreamable too.
#include <yaml-cpp/eventhandler.h>

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "services/flightplan/list_splice.hpp"
#include "services/flightplan/plan_parser.hpp"
#include "services/flightplan/yaml_tree.hpp"

namespace airseg::flightplan {

struct NotStreamable {};

class PlanEventReader final : public YAML::EventHandler {
  public:
    PlanEventReader(PlanParser& parser, const LoadOptions& options, bool stream);
    ~PlanEventReader() override;

    /// The parser reads `text` through a SplicedBuffer made with `splice` (both outlive the reader).
    void splice(std::string_view text, const ListSplice& splice);

    /// After the parser's HandleNextDocument (or without any document). With a splice, throws NotStreamable
    /// unless the stand-in was read as the plan's list (it may have been inside a scalar).
    LoadResult result();

    void OnDocumentStart(const YAML::Mark&) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override;
    void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override;
    void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  const std::string& value) override;
    void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                         YAML::EmitterStyle::value style) override;
    void OnSequenceEnd() override;
    void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                    YAML::EmitterStyle::value style) override;
    void OnMapEnd() override;

  private:
    struct Level;
    enum class Role : unsigned char { Plain, Root, PlanBody, Item, Body, BlockItem };
    enum class Pending : unsigned char { None, PlanValue, BodyValue, PlanElements, PlanBlocks, Elements };
    struct Open {
        Role role = Role::Plain;
        std::size_t keys = 0;
        bool streamed = false;  // its "elements" list (Root: the plan) was streamed
        bool elements = false;  // an "elements" key was seen
        bool blocks = false;    // PlanBody: a "blocks" key was seen
        bool blocks_streamed = false;
    };

    Level& level() { return *levels_.back(); }
    /// Bookkeeping for a node about to be attached: when it is a key of a mapping the reader follows, note
    /// what its value will be (pending_), or stop when the layout cannot be streamed.
    void before_node(const YNode* key, bool is_key);
    bool next_is_key() const;
    void start(YNode::Type type, const YAML::Mark& mark, YAML::anchor_t anchor);
    void end();
    void finished(const YNode* tree, const Open& role);
    void list_ended();
    /// A mark of the text being parsed as a mark of the original text.
    YAML::Mark place(const YAML::Mark& mark) const;
    void read_batches();

    PlanParser& parser_;
    const LoadOptions& options_;
    bool stream_;
    std::unique_ptr<YAnchors> anchors_;
    std::vector<std::unique_ptr<Level>> levels_;
    Pending pending_ = Pending::None;
    std::optional<LoadResult> result_;
    std::string_view text_;
    const ListSplice* splice_ = nullptr;
    const ListSplice::Batch* batch_ = nullptr;  // the batch being read
    bool spliced_ = false;
};

}  // namespace airseg::flightplan
