#include "services/flightplan/yaml_tree.hpp"

#include <yaml-cpp/yaml.h>

namespace airseg::flightplan {

const std::string& YRef::Scalar() const {
    static const std::string kEmpty;
    return IsScalar() ? node_->scalar : kEmpty;
}

std::size_t YRef::size() const {
    if (IsSequence()) {
        return node_->items.size();
    }
    if (IsMap()) {
        return node_->items.size() / 2;
    }
    return 0;
}

YRef YRef::operator[](std::size_t index) const {
    if (!IsSequence() || index >= node_->items.size()) {
        return {};
    }
    return YRef(node_->items[index]);
}

YRef YRef::operator[](std::string_view wanted) const {
    if (!IsMap()) {
        return {};
    }
    for (std::size_t i = 0; i + 1 < node_->items.size(); i += 2) {
        const YNode* k = node_->items[i];
        if (k->type == YNode::Type::Scalar && k->scalar == wanted) {
            return YRef(node_->items[i + 1]);
        }
    }
    return {};
}

bool decode_double(const YRef& node, double& out) {
    return node.IsScalar() && YAML::convert<double>::decode(YAML::Node(node.Scalar()), out);
}

bool decode_bool(const YRef& node, bool& out) {
    return node.IsScalar() && YAML::convert<bool>::decode(YAML::Node(node.Scalar()), out);
}

YNode* YTreeBuilder::make(YNode::Type type, const YAML::Mark& mark, YAML::anchor_t anchor) {
    YNode& n = arena_.emplace_back();
    n.type = type;
    n.mark = mark;
    if (anchor != YAML::NullAnchor) {
        if (anchors_.by_id.size() < anchor) {
            anchors_.by_id.resize(anchor, nullptr);
        }
        anchors_.by_id[anchor - 1] = &n;
        arena_anchored_ = true;
    }
    return &n;
}

const YNode* YTreeBuilder::attach(const YNode* node) {
    if (open_.empty()) {
        return node;
    }
    open_.back()->items.push_back(node);
    return nullptr;
}

const YNode* YTreeBuilder::null(const YAML::Mark& mark, YAML::anchor_t anchor) {
    return attach(make(YNode::Type::Null, mark, anchor));
}

const YNode* YTreeBuilder::scalar(const YAML::Mark& mark, YAML::anchor_t anchor, const std::string& value) {
    YNode* n = make(YNode::Type::Scalar, mark, anchor);
    n->scalar = value;
    return attach(n);
}

const YNode* YTreeBuilder::alias(YAML::anchor_t anchor) {
    // yaml-cpp's parser refuses unknown anchors before this point.
    const YNode* target =
        anchor >= 1 && anchor <= anchors_.by_id.size() ? anchors_.by_id[anchor - 1] : nullptr;
    if (target == nullptr) {
        target = make(YNode::Type::Null, YAML::Mark::null_mark(), YAML::NullAnchor);
    }
    return attach(target);
}

void YTreeBuilder::begin(YNode::Type type, const YAML::Mark& mark, YAML::anchor_t anchor) {
    YNode* n = make(type, mark, anchor);
    attach(n);
    open_.push_back(n);
}

const YNode* YTreeBuilder::end() {
    const YNode* n = open_.back();
    open_.pop_back();
    return open_.empty() ? n : nullptr;
}

void YTreeBuilder::release() {
    if (!open_.empty()) {
        return;
    }
    if (arena_anchored_) {
        anchors_.kept.push_back(std::move(arena_));
    }
    arena_.clear();
    arena_anchored_ = false;
}

}  // namespace airseg::flightplan
