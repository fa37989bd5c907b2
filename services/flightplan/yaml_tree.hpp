#pragma once
// A small YAML document tree built from yaml-cpp's parser events, read through YRef, a view with the
// subset of YAML::Node's interface the plan loader uses (same types, marks, first-match key lookup, duplicate
// keys kept). Unlike YAML::Load, a tree can be built for one part of a document at a time: the loader builds
// each element of a long list, reads it, and drops it.
#include <yaml-cpp/anchor.h>
#include <yaml-cpp/mark.h>

#include <cstddef>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

namespace airseg::flightplan {

struct YNode {
    enum class Type : unsigned char { Null, Scalar, Sequence, Map };
    Type type = Type::Null;
    YAML::Mark mark = YAML::Mark::null_mark();
    std::string scalar;
    std::vector<const YNode*> items;  // Sequence: the items; Map: key, value, key, value, ...
};

/// A possibly undefined node (a missing key), as YAML::Node's zombie nodes.
class YRef {
  public:
    YRef() = default;
    explicit YRef(const YNode* node) : node_(node) {}

    // Spelled as YAML::Node's members, whose behaviour these copy, so the parser reads as yaml-cpp code.
    // NOLINTBEGIN(readability-identifier-naming)
    bool IsDefined() const { return node_ != nullptr; }
    bool IsNull() const { return is(YNode::Type::Null); }
    bool IsScalar() const { return is(YNode::Type::Scalar); }
    bool IsSequence() const { return is(YNode::Type::Sequence); }
    bool IsMap() const { return is(YNode::Type::Map); }
    const std::string& Scalar() const;
    YAML::Mark Mark() const { return node_ ? node_->mark : YAML::Mark::null_mark(); }
    // NOLINTEND(readability-identifier-naming)
    /// Items of a sequence, pairs of a mapping, 0 otherwise.
    std::size_t size() const;
    YRef operator[](std::size_t index) const;
    /// The value of the first pair whose key is a scalar equal to `key`.
    YRef operator[](std::string_view key) const;
    YRef key(std::size_t pair) const { return YRef(node_->items[2 * pair]); }
    YRef value(std::size_t pair) const { return YRef(node_->items[2 * pair + 1]); }

  private:
    bool is(YNode::Type t) const { return node_ != nullptr && node_->type == t; }
    const YNode* node_ = nullptr;
};

/// YAML::convert<double> and <bool> on a scalar, so numbers and booleans read exactly as with YAML::Node.
bool decode_double(const YRef& node, double& out);
bool decode_bool(const YRef& node, bool& out);

/// Anchored nodes of one document, shared by the builders that read its parts: an alias may point into a
/// part read earlier, so arenas holding anchored nodes are kept here until the document is done.
struct YAnchors {
    std::vector<const YNode*> by_id;  // anchor id - 1
    std::deque<std::deque<YNode>> kept;
};

/// Builds trees from events. Nodes live in an arena; anchored nodes stay reachable for later aliases (an
/// alias is the anchored node itself, as in yaml-cpp). Open collections are kept on a stack so that a
/// caller can start a tree at any event and take it when its last collection closes.
class YTreeBuilder {
  public:
    explicit YTreeBuilder(YAnchors& anchors) : anchors_(anchors) {}

    /// Adds a leaf; returns it when it completes a tree (no collection open), else nullptr.
    const YNode* null(const YAML::Mark& mark, YAML::anchor_t anchor);
    const YNode* scalar(const YAML::Mark& mark, YAML::anchor_t anchor, const std::string& value);
    const YNode* alias(YAML::anchor_t anchor);
    void begin(YNode::Type type, const YAML::Mark& mark, YAML::anchor_t anchor);
    /// Closes the innermost collection; returns it when it completes a tree, else nullptr.
    const YNode* end();

    bool building() const { return !open_.empty(); }
    std::size_t depth() const { return open_.size(); }
    /// The innermost and the outermost open collection.
    YNode* top() const { return open_.back(); }
    const YNode* root() const { return open_.front(); }
    /// Frees the nodes of finished trees unless one holds an anchor (a later alias may point into it).
    void release();

  private:
    YNode* make(YNode::Type type, const YAML::Mark& mark, YAML::anchor_t anchor);
    const YNode* attach(const YNode* node);

    YAnchors& anchors_;
    std::deque<YNode> arena_;
    bool arena_anchored_ = false;
    std::vector<YNode*> open_;
};

}  // namespace airseg::flightplan
