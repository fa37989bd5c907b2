#include "services/flightplan/plan_stream.hpp"

#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>

#include <istream>
#include <utility>

#include "base/utf8.hpp"

namespace airseg::flightplan {

// One level per list being streamed (level 0 is the document). A level's builder holds the trees of that
// level: the document skeleton at level 0, the item being read in a list's level. `open` runs parallel to the
// builder's open collections.
struct PlanEventReader::Level {
    enum class Kind : unsigned char { Document, Elements, Blocks, Skip };
    Level(YAnchors& anchors, Kind k) : builder(anchors), kind(k) {}
    YTreeBuilder builder;
    std::vector<Open> open;
    Kind kind;
    std::uint32_t parent = kNoNode;
    std::string path;
    YNode list;  // the list's own node (type and mark), for diagnostics about it
    std::size_t items = 0;
    std::size_t skip_depth = 0;
};

PlanEventReader::PlanEventReader(PlanParser& parser, const LoadOptions& options, bool stream)
    : parser_(parser), options_(options), stream_(stream), anchors_(std::make_unique<YAnchors>()) {
    levels_.push_back(std::make_unique<Level>(*anchors_, Level::Kind::Document));
}

PlanEventReader::~PlanEventReader() = default;

namespace {

/// Passes a batch's items to the reader: the batch is one block list, whose own start and end are the
/// stand-in's business.
class BatchEvents final : public YAML::EventHandler {
  public:
    explicit BatchEvents(YAML::EventHandler& reader) : reader_(reader) {}

    bool was_one_list() const { return lists_ == 1 && depth_ == 0; }

    void OnDocumentStart(const YAML::Mark&) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override {
        item();
        reader_.OnNull(mark, anchor);
    }
    void OnAlias(const YAML::Mark&, YAML::anchor_t) override { throw NotStreamable{}; }
    void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  const std::string& value) override {
        item();
        reader_.OnScalar(mark, tag, anchor, value);
    }
    void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                         YAML::EmitterStyle::value style) override {
        if (depth_++ == 0) {
            if (++lists_ != 1 || style != YAML::EmitterStyle::Block || anchor != YAML::NullAnchor) {
                throw NotStreamable{};
            }
            return;
        }
        reader_.OnSequenceStart(mark, tag, anchor, style);
    }
    void OnSequenceEnd() override {
        if (--depth_ > 0) {
            reader_.OnSequenceEnd();
        }
    }
    void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                    YAML::EmitterStyle::value style) override {
        item();
        ++depth_;
        reader_.OnMapStart(mark, tag, anchor, style);
    }
    void OnMapEnd() override {
        --depth_;
        reader_.OnMapEnd();
    }

  private:
    void item() const {
        if (depth_ == 0) {
            throw NotStreamable{};  // the batch is not a list
        }
    }

    YAML::EventHandler& reader_;
    int depth_ = 0;
    int lists_ = 0;
};

}  // namespace

void PlanEventReader::splice(std::string_view text, const ListSplice& splice) {
    text_ = text;
    splice_ = &splice;
}

YAML::Mark PlanEventReader::place(const YAML::Mark& mark) const {
    if (batch_ != nullptr && !mark.is_null()) {
        // A batch that ends the text is the text's own end, where its parser's marks are the whole text's.
        if (!batch_->ends_text && static_cast<std::size_t>(mark.pos) >= batch_->end - batch_->begin) {
            return batch_->after;
        }
        YAML::Mark m = mark;
        m.pos += static_cast<int>(batch_->begin);
        m.line += batch_->first_line;
        return m;
    }
    return splice_ != nullptr && batch_ == nullptr ? splice_->original(mark) : mark;
}

void PlanEventReader::read_batches() {
    for (const ListSplice::Batch& batch : splice_->batches) {
        BatchBuffer buffer(text_, batch);
        std::istream in(&buffer);
        YAML::Parser parser(in);
        BatchEvents events(*this);
        batch_ = &batch;
        parser.HandleNextDocument(events);
        batch_ = nullptr;
        if (!events.was_one_list()) {
            throw NotStreamable{};
        }
    }
}

LoadResult PlanEventReader::result() {
    if (splice_ != nullptr && !spliced_) {
        throw NotStreamable{};
    }
    if (!result_) {
        result_ = parser_.run(YRef(), options_);  // no document at all
    }
    return std::move(*result_);
}

bool PlanEventReader::next_is_key() const {
    const Level& l = *levels_.back();
    return l.builder.building() && l.builder.top()->type == YNode::Type::Map &&
           l.builder.top()->items.size() % 2 == 0;
}

void PlanEventReader::before_node(const YNode* key, bool is_key) {
    Level& l = level();
    if (!stream_ || l.open.empty()) {
        return;
    }
    Open& o = l.open.back();
    if (!is_key) {
        return;
    }
    ++o.keys;
    const bool scalar = key != nullptr && key->type == YNode::Type::Scalar;
    const std::string_view name = scalar ? std::string_view(key->scalar) : std::string_view();
    switch (o.role) {
        case Role::Plain:
            break;
        case Role::Root:
            if (o.streamed) {
                throw NotStreamable{};  // a key after the plan: its check comes first in document order
            }
            if (o.keys == 1 && name == "plan") {
                pending_ = Pending::PlanValue;
            }
            break;
        case Role::PlanBody:
            if (o.streamed) {
                if (name != "blocks" || o.blocks) {
                    throw NotStreamable{};
                }
                o.blocks = true;
                pending_ = Pending::PlanBlocks;
            } else if (name == "blocks") {
                o.blocks = true;  // before the elements: read whole, checked after them
            } else if (name == "elements" && !std::exchange(o.elements, true)) {
                pending_ = Pending::PlanElements;  // the first one: lookups find the first of duplicate keys
            }
            break;
        case Role::Item:
            if (o.streamed) {
                throw NotStreamable{};  // a second key: the element is refused as a whole
            }
            if (o.keys == 1 && (name == "repeat" || name == "block")) {
                pending_ = Pending::BodyValue;
            }
            break;
        case Role::Body:
        case Role::BlockItem:
            if (o.streamed) {
                throw NotStreamable{};
            }
            if (name == "elements" && !std::exchange(o.elements, true)) {
                pending_ = Pending::Elements;
            }
            break;
    }
}

void PlanEventReader::OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) {
    Level& l = level();
    if (l.kind == Level::Kind::Skip) {
        return;
    }
    pending_ = Pending::None;
    before_node(nullptr, next_is_key());
    if (const YNode* tree = l.builder.null(place(mark), anchor)) {
        finished(tree, Open{});
    }
}

void PlanEventReader::OnAlias(const YAML::Mark&, YAML::anchor_t anchor) {
    Level& l = level();
    if (l.kind == Level::Kind::Skip) {
        return;
    }
    pending_ = Pending::None;
    before_node(nullptr, next_is_key());
    if (const YNode* tree = l.builder.alias(anchor)) {
        finished(tree, Open{});
    }
}

void PlanEventReader::OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                               const std::string& value) {
    Level& l = level();
    if (l.kind == Level::Kind::Skip) {
        return;
    }
    if (const auto bad = first_invalid_utf8(value)) {
        // Every text of a plan reaches JSON documents (status, plan.show), whose dump would throw on it.
        throw YAML::Exception(place(mark), "text that is not valid UTF-8 (byte " + std::to_string(*bad + 1) +
                                               " of a " + (next_is_key() ? "key" : "value") + ")");
    }
    pending_ = Pending::None;
    const bool key = next_is_key();
    YNode probe;
    probe.type = YNode::Type::Scalar;
    probe.scalar = value;
    before_node(&probe, key);
    if (const YNode* tree = l.builder.scalar(place(mark), anchor, value)) {
        finished(tree, Open{});
    }
}

void PlanEventReader::OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                                      YAML::EmitterStyle::value) {
    const bool stand_in =
        splice_ != nullptr && batch_ == nullptr && !mark.is_null() &&
        static_cast<std::size_t>(mark.pos) >= splice_->cut_begin &&
        static_cast<std::size_t>(mark.pos) < splice_->cut_begin + ListSplice::kStandIn.size();
    if (stand_in != (pending_ == Pending::PlanElements && stream_ && splice_ != nullptr &&
                     batch_ == nullptr && !spliced_ && level().kind == Level::Kind::Document)) {
        throw NotStreamable{};  // the list is not where the splice was made, or the stand-in is read as data
    }
    start(YNode::Type::Sequence, place(mark), anchor);
    if (stand_in) {
        spliced_ = true;
        read_batches();
    }
}

void PlanEventReader::OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                                 YAML::EmitterStyle::value) {
    start(YNode::Type::Map, place(mark), anchor);
}

void PlanEventReader::start(YNode::Type type, const YAML::Mark& mark, YAML::anchor_t anchor) {
    Level& l = level();
    if (l.kind == Level::Kind::Skip) {
        ++l.skip_depth;
        return;
    }
    const Pending pending = std::exchange(pending_, Pending::None);
    const bool plain_list = type == YNode::Type::Sequence && anchor == YAML::NullAnchor;
    const bool plain_map = type == YNode::Type::Map && anchor == YAML::NullAnchor;
    auto push_list = [&](Level::Kind kind, std::uint32_t parent, std::string path) {
        auto next = std::make_unique<Level>(*anchors_, kind);
        next->parent = parent;
        next->path = std::move(path);
        next->list.type = YNode::Type::Sequence;
        next->list.mark = mark;
        levels_.push_back(std::move(next));
    };
    if (stream_ && plain_list && !l.open.empty()) {
        Open& holder = l.open.back();
        switch (pending) {
            case Pending::PlanElements: {
                const auto target = parser_.begin_plan(YRef(l.builder.root()));
                holder.streamed = true;
                l.open.front().streamed = true;
                push_list(Level::Kind::Elements, target.id, target.path);
                return;
            }
            case Pending::PlanBlocks: {
                YNode list;
                list.type = YNode::Type::Sequence;
                list.mark = mark;
                parser_.begin_blocks(YRef(&list));
                holder.blocks_streamed = true;
                push_list(Level::Kind::Blocks, kNoNode, "plan.blocks");
                return;
            }
            case Pending::Elements: {
                holder.streamed = true;
                if (holder.role == Role::BlockItem) {
                    const auto target = parser_.block_head(YRef(l.builder.root()), l.items);
                    push_list(Level::Kind::Elements, target->id, target->path);
                    return;
                }
                // The body of a repeat/block element: the element is the mapping around it.
                l.open[l.open.size() - 2].streamed = true;
                const auto target = parser_.element_head(YRef(l.builder.root()), l.parent,
                                                         l.path + "[" + std::to_string(l.items) + "]");
                if (target) {
                    push_list(Level::Kind::Elements, target->id, target->path);
                } else {
                    push_list(Level::Kind::Skip, kNoNode, {});
                }
                return;
            }
            default:
                break;
        }
    }
    const bool key = next_is_key();
    before_node(nullptr, key);
    Open o;
    if (stream_) {
        if (!l.builder.building()) {
            if (l.kind == Level::Kind::Document && plain_map) {
                o.role = Role::Root;
            } else if (l.kind == Level::Kind::Elements && plain_map) {
                o.role = Role::Item;
            } else if (l.kind == Level::Kind::Blocks && plain_map) {
                o.role = Role::BlockItem;
            }
        } else if (plain_map && pending == Pending::PlanValue) {
            o.role = Role::PlanBody;
        } else if (plain_map && pending == Pending::BodyValue) {
            o.role = Role::Body;
        }
    }
    l.builder.begin(type, mark, anchor);
    l.open.push_back(o);
}

void PlanEventReader::OnSequenceEnd() {
    end();
}

void PlanEventReader::OnMapEnd() {
    end();
}

void PlanEventReader::end() {
    Level& l = level();
    pending_ = Pending::None;
    if (l.kind == Level::Kind::Skip) {
        if (l.skip_depth == 0) {
            list_ended();
        } else {
            --l.skip_depth;
        }
        return;
    }
    if (l.kind != Level::Kind::Document && !l.builder.building()) {
        list_ended();
        return;
    }
    const Open o = l.open.back();
    l.open.pop_back();
    // The blocks follow the elements in the parser's order: read whole unless streamed after them.
    if (o.role == Role::PlanBody && o.streamed && !o.blocks_streamed) {
        parser_.parse_blocks(YRef(l.builder.top())["blocks"], "plan.blocks");
    }
    if (const YNode* tree = l.builder.end()) {
        finished(tree, o);
    }
}

void PlanEventReader::finished(const YNode* tree, const Open& role) {
    Level& l = level();
    switch (l.kind) {
        case Level::Kind::Document:
            if (role.role == Role::Root && role.streamed) {
                result_ = parser_.finish(options_);
            } else {
                result_ = parser_.run(YRef(tree), options_);
            }
            return;
        case Level::Kind::Elements:
            if (!role.streamed) {
                parser_.parse_element(YRef(tree), l.parent, l.path + "[" + std::to_string(l.items) + "]");
            }
            break;
        case Level::Kind::Blocks:
            if (!role.streamed) {
                parser_.parse_block(YRef(tree), l.items);
            }
            break;
        case Level::Kind::Skip:
            break;
    }
    ++l.items;
    l.builder.release();
}

void PlanEventReader::list_ended() {
    Level& l = level();
    if (l.kind == Level::Kind::Elements && l.items == 0) {
        parser_.empty_list(YRef(&l.list), l.parent, l.path);
    }
    const YAML::Mark mark = l.list.mark;
    l.builder.release();
    levels_.pop_back();
    // Stands for the list in the mapping that held it, so that later keys pair up.
    level().builder.null(mark, YAML::NullAnchor);
}

}  // namespace airseg::flightplan
