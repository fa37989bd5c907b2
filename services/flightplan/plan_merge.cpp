#include "services/flightplan/plan_merge.hpp"

#include <yaml-cpp/emitter.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cstddef>
#include <istream>
#include <optional>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

#include "services/flightplan/text_stream.hpp"

namespace airseg::flightplan {

// A named namespace inside the anonymous one: this file is compiled in a unity batch with others that
// have helpers of the same names.
namespace {
namespace merge {

using YAML::anchor_t;
using Style = YAML::EmitterStyle::value;

constexpr std::array<std::string_view, 3> kLists = {"elements", "blocks", "no_fly"};
constexpr int kNone = -1;
constexpr int kPlanKey = -2;

/// A layout the streaming merge cannot follow (see append_plan_text); both plans are merged whole instead.
struct NeedsWholeTree {};
/// Stops reading the appended text once the list being copied has ended: nothing after it is needed.
struct ListCopied {};

// ------------------------------------------------------------------------------------------------------
// The merge as it was: both documents as yaml-cpp trees (append_plan_text_as_trees).

void append_list(YAML::Node into, const YAML::Node& from) {
    if (!from.IsSequence()) {
        return;
    }
    for (const auto& item : from) {
        into.push_back(YAML::Clone(item));
    }
}

}  // namespace merge
}  // namespace

MergedPlan append_plan_text_as_trees(std::string_view running, std::string_view appended) {
    using namespace merge;
    MergedPlan out;
    out.whole_tree = true;
    try {
        YAML::Node base = YAML::Load(std::string(running));
        const YAML::Node extra = YAML::Load(std::string(appended));
        YAML::Node plan = base["plan"];
        const YAML::Node more = extra["plan"];
        if (!plan.IsMap() || !more.IsMap()) {
            out.error = "both plans need a 'plan' mapping";
            return out;
        }
        for (const std::string_view key : kLists) {
            const std::string k(key);
            if (!more[k].IsDefined() || more[k].IsNull()) {
                continue;
            }
            if (!plan[k].IsDefined() || plan[k].IsNull()) {
                plan[k] = YAML::Node(YAML::NodeType::Sequence);
            }
            YAML::Node list = plan[k];
            append_list(list, more[k]);
        }
        YAML::Emitter emitter;
        emitter << base;
        if (!emitter.good()) {
            out.error = "cannot write the merged plan: " + emitter.GetLastError();
            return out;
        }
        out.text = std::string(emitter.c_str()) + "\n";
    } catch (const YAML::Exception& e) {
        out.error = std::string("cannot merge the plans: ") + e.what();
    }
    return out;
}

namespace {
namespace merge {

// ------------------------------------------------------------------------------------------------------
// Input and output.

/// The merged text, written straight into the string that is returned. It is reserved once; what does not
/// fit is only counted and the merge runs again at the exact size, because growing the string while the
/// parser is alive would hold the old and the new buffer together (three times the text).
class TextSink : public std::streambuf {
  public:
    explicit TextSink(std::size_t capacity) { text_.reserve(capacity); }

    bool overflowed() const { return overflowed_; }
    std::size_t size() const { return size_; }
    std::string take() { return std::move(text_); }

  protected:
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        const auto count = static_cast<std::size_t>(n);
        size_ += count;
        // One byte stays free for the final newline.
        if (!overflowed_ && text_.size() + count < text_.capacity()) {
            text_.append(s, count);
        } else {
            overflowed_ = true;
        }
        return n;
    }
    int_type overflow(int_type ch) override {
        if (traits_type::eq_int_type(ch, traits_type::eof())) {
            return traits_type::not_eof(ch);
        }
        const char c = traits_type::to_char_type(ch);
        xsputn(&c, 1);
        return ch;
    }

  private:
    std::string text_;
    std::size_t size_ = 0;
    bool overflowed_ = false;
};

/// Writes parser events with an Emitter, as yaml-cpp's EmitFromEvents does (the shared library does not
/// export it): same manipulators in the same order, so the text is what `emitter << node` wrote before.
class EventWriter {
  public:
    explicit EventWriter(YAML::Emitter& emitter) : emitter_(emitter) {}

    void null(anchor_t anchor) {
        begin_node();
        props("", anchor);
        emitter_ << YAML::Null;
    }
    void alias(anchor_t anchor) {
        begin_node();
        emitter_ << YAML::Alias(std::to_string(anchor));
    }
    void scalar(const std::string& tag, anchor_t anchor, const std::string& value) {
        begin_node();
        props(tag, anchor);
        emitter_ << value;
    }
    void begin(bool map, const std::string& tag, anchor_t anchor, Style style) {
        begin_node();
        props(tag, anchor);
        if (style == Style::Block) {
            emitter_ << YAML::Block;
        } else if (style == Style::Flow) {
            emitter_ << YAML::Flow;
        }
        // The node's style must not outlive it.
        emitter_.RestoreGlobalModifiedSettings();
        emitter_ << (map ? YAML::BeginMap : YAML::BeginSeq);
        states_.push_back(map ? State::Key : State::Entry);
    }
    void end() {
        emitter_ << (states_.back() == State::Entry ? YAML::EndSeq : YAML::EndMap);
        states_.pop_back();
    }

  private:
    enum class State : unsigned char { Entry, Key, Value };

    void begin_node() {
        if (states_.empty()) {
            return;
        }
        State& s = states_.back();
        if (s == State::Key) {
            emitter_ << YAML::Key;
            s = State::Value;
        } else if (s == State::Value) {
            emitter_ << YAML::Value;
            s = State::Key;
        }
    }
    void props(const std::string& tag, anchor_t anchor) {
        // "?" and "!" are the parser's non-specific tags: the emitter chooses again.
        if (!tag.empty() && tag != "?" && tag != "!") {
            emitter_ << YAML::VerbatimTag(tag);
        }
        if (anchor != 0) {
            emitter_ << YAML::Anchor(std::to_string(anchor));
        }
    }

    YAML::Emitter& emitter_;
    std::vector<State> states_;
};

/// The writer, fed with both documents' events. Each parser numbers its anchors from 1, so the running
/// plan's anchor n is written as 2n-1 and the appended plan's as 2n.
class Output {
  public:
    Output(YAML::Emitter& emitter, std::size_t appended_anchors)
        : write(emitter), written_(appended_anchors, false) {}

    static anchor_t running(anchor_t a) { return a == 0 ? 0 : 2 * a - 1; }
    static anchor_t appended(anchor_t a) { return 2 * a; }

    /// The anchor to write on an appended node. A node can be written twice (copied for an alias before
    /// its own list is copied); the second copy goes without the anchor, and later aliases refer to the
    /// first, which is the same node.
    anchor_t define(anchor_t a) {
        if (a == 0) {
            return 0;
        }
        if (a > written_.size()) {
            throw NeedsWholeTree{};
        }
        if (written_[a - 1]) {
            return 0;
        }
        written_[a - 1] = true;
        return appended(a);
    }
    bool written(anchor_t a) const { return a != 0 && a <= written_.size() && written_[a - 1]; }

    EventWriter write;

  private:
    std::vector<bool> written_;
};

// ------------------------------------------------------------------------------------------------------
// Where a node sits in a plan document, as the whole-tree merge looked things up: the first "plan" key of
// the top-level mapping, and in that mapping the first key of each list (YAML::Node's operator[] returns
// the first of duplicate keys).

enum class Place : unsigned char {
    Other,
    Root,  // the document's top node
    Plan,  // the value of the plan key
    List,  // the value of a list key of the plan
    Item,  // an item of such a list, or anything inside one
};

struct Slot {
    Place place = Place::Other;
    int list = kNone;
};

class PlanWalker {
  public:
    /// Where the node whose event is being handled sits.
    Slot slot() const {
        if (stack_.empty()) {
            return {Place::Root, kNone};
        }
        const Frame& p = stack_.back();
        if (p.place == Place::List || p.place == Place::Item) {
            return {Place::Item, p.list};
        }
        if (p.map && !p.want_key) {
            if (p.pending == kPlanKey) {
                return {Place::Plan, kNone};
            }
            if (p.pending >= 0) {
                return {Place::List, p.pending};
            }
        }
        return {};
    }
    /// Where the innermost open collection sits.
    Slot open_slot() const { return {stack_.back().place, stack_.back().list}; }
    /// The node being handled is an item of a list (not something inside one).
    bool directly_in_list() const { return !stack_.empty() && stack_.back().place == Place::List; }
    std::size_t depth() const { return stack_.size(); }
    bool plan_seen() const { return plan_seen_; }
    bool plan_is_map() const { return plan_is_map_; }
    bool has_list(int k) const { return list_seen_[static_cast<std::size_t>(k)]; }

    /// After a scalar (`scalar` set), null or alias event.
    void leaf(const std::string* scalar, bool alias) {
        // yaml-cpp matches an alias used as a key (or as the plan) by the node it stands for; following
        // that would mean keeping every anchored node of the document.
        if (alias && slot().place == Place::Plan) {
            throw NeedsWholeTree{};
        }
        if (!stack_.empty()) {
            Frame& p = stack_.back();
            if (p.map && p.want_key && (p.place == Place::Root || p.place == Place::Plan)) {
                if (alias) {
                    throw NeedsWholeTree{};
                }
                if (scalar != nullptr) {
                    p.pending = match(p.place, *scalar);
                }
            }
        }
        advance();
    }
    void open(bool map) {
        Slot s = slot();
        if (((s.place == Place::Root || s.place == Place::Plan) && !map) || (s.place == Place::List && map)) {
            s = {};
        }
        if (s.place == Place::Plan) {
            plan_is_map_ = true;
        }
        stack_.push_back({s.place, s.list, map});
    }
    void close() {
        stack_.pop_back();
        advance();
    }

  private:
    struct Frame {
        Place place;
        int list;
        bool map;
        bool want_key = true;
        int pending = kNone;  // what the value after the current key is
    };

    int match(Place where, const std::string& key) {
        if (where == Place::Root) {
            if (plan_seen_ || key != "plan") {
                return kNone;
            }
            plan_seen_ = true;
            return kPlanKey;
        }
        for (std::size_t k = 0; k < kLists.size(); ++k) {
            if (key == kLists[k]) {
                if (list_seen_[k]) {
                    return kNone;
                }
                list_seen_[k] = true;
                return static_cast<int>(k);
            }
        }
        return kNone;
    }
    void advance() {
        if (stack_.empty() || !stack_.back().map) {
            return;
        }
        Frame& p = stack_.back();
        if (p.want_key) {
            p.want_key = false;
        } else {
            p.want_key = true;
            p.pending = kNone;
        }
    }

    std::vector<Frame> stack_;
    bool plan_seen_ = false;
    bool plan_is_map_ = false;
    std::array<bool, 3> list_seen_{};
};

// ------------------------------------------------------------------------------------------------------
// The appended plan, read once before the merge: what each of its lists is, and which anchored nodes
// outside a list's items those items refer to (directly, or through such a node), so that copying the
// list keeps exactly those nodes' events.

struct ListFacts {
    enum class Value : unsigned char { Missing, Null, Sequence, Other };
    Value value = Value::Missing;
    bool has_items = false;
    std::vector<bool> needs;  // by anchor - 1
    bool any_needs = false;
};

struct AppendedFacts {
    bool root_scalar = false;
    YAML::Mark root_mark = YAML::Mark::null_mark();
    bool has_plan = false;
    bool plan_is_map = false;
    std::size_t anchors = 0;
    std::array<ListFacts, 3> lists;

    const ListFacts& list(int k) const { return lists[static_cast<std::size_t>(k)]; }
    /// The running plan gets this list (empty when the appended value is not a list, as before).
    bool adds(int k) const {
        return list(k).value == ListFacts::Value::Sequence || list(k).value == ListFacts::Value::Other;
    }
    bool has_items(int k) const { return list(k).has_items; }
};

class FactsReader final : public YAML::EventHandler {
  public:
    AppendedFacts finish() {
        facts_.has_plan = walk_.plan_seen();
        facts_.plan_is_map = walk_.plan_is_map();
        facts_.anchors = anchors_.size();
        for (std::size_t k = 0; k < kLists.size(); ++k) {
            ListFacts& list = facts_.lists[k];
            list.needs.assign(anchors_.size(), false);
            std::vector<anchor_t> unvisited = std::move(seeds_[k]);
            while (!unvisited.empty()) {
                const anchor_t a = unvisited.back();
                unvisited.pop_back();
                if (list.needs[a - 1]) {
                    continue;
                }
                list.needs[a - 1] = true;
                list.any_needs = true;
                const auto& refs = anchors_[a - 1].outer_refs;
                unvisited.insert(unvisited.end(), refs.begin(), refs.end());
            }
        }
        return std::move(facts_);
    }

    void OnDocumentStart(const YAML::Mark&) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, anchor_t anchor) override {
        node(walk_.slot(), anchor, ListFacts::Value::Null);
        walk_.leaf(nullptr, false);
    }
    void OnAlias(const YAML::Mark&, anchor_t target) override {
        if (target == 0 || target > anchors_.size()) {
            throw NeedsWholeTree{};
        }
        const Slot s = walk_.slot();
        const Anchor& t = anchors_[target - 1];
        node(s, 0, t.value);
        for (const Open& o : open_) {
            if (o.anchor != 0 && target < o.anchor) {
                anchors_[o.anchor - 1].outer_refs.push_back(target);
            }
        }
        if (s.place == Place::Item && t.list != s.list) {
            seeds_[static_cast<std::size_t>(s.list)].push_back(target);
        }
        if (s.place == Place::List) {
            facts_.lists[static_cast<std::size_t>(s.list)].has_items = t.has_items;
            seeds_[static_cast<std::size_t>(s.list)].push_back(target);
        }
        walk_.leaf(nullptr, true);
    }
    void OnScalar(const YAML::Mark& mark, const std::string&, anchor_t anchor,
                  const std::string& value) override {
        const Slot s = walk_.slot();
        if (s.place == Place::Root) {
            facts_.root_scalar = true;
            facts_.root_mark = mark;
        }
        node(s, anchor, ListFacts::Value::Other);
        walk_.leaf(&value, false);
    }
    void OnSequenceStart(const YAML::Mark&, const std::string&, anchor_t anchor, Style) override {
        node(walk_.slot(), anchor, ListFacts::Value::Sequence);
        open_.push_back({anchor});
        walk_.open(false);
    }
    void OnSequenceEnd() override { end(); }
    void OnMapStart(const YAML::Mark&, const std::string&, anchor_t anchor, Style) override {
        node(walk_.slot(), anchor, ListFacts::Value::Other);
        open_.push_back({anchor});
        walk_.open(true);
    }
    void OnMapEnd() override { end(); }

  private:
    struct Anchor {
        int list = kNone;  // the list whose items hold it
        ListFacts::Value value = ListFacts::Value::Other;
        bool has_items = false;
        std::vector<anchor_t> outer_refs;  // aliases inside it to nodes anchored before it
    };
    struct Open {
        anchor_t anchor = 0;
        bool any = false;  // has a child
    };

    void node(const Slot& s, anchor_t anchor, ListFacts::Value value) {
        if (!open_.empty()) {
            open_.back().any = true;
        }
        if (s.place == Place::Item && walk_.directly_in_list()) {
            facts_.lists[static_cast<std::size_t>(s.list)].has_items = true;
        }
        if (s.place == Place::List) {
            facts_.lists[static_cast<std::size_t>(s.list)].value = value;
        }
        if (anchor != 0) {
            if (anchors_.size() < anchor) {
                anchors_.resize(anchor);
            }
            anchors_[anchor - 1].list = s.place == Place::Item ? s.list : kNone;
            anchors_[anchor - 1].value = value;
        }
    }
    void end() {
        const Open o = open_.back();
        open_.pop_back();
        if (o.anchor != 0) {
            anchors_[o.anchor - 1].has_items = o.any;
        }
        walk_.close();
    }

    PlanWalker walk_;
    AppendedFacts facts_;
    std::vector<Anchor> anchors_;
    std::vector<Open> open_;
    std::array<std::vector<anchor_t>, 3> seeds_;
};

// ------------------------------------------------------------------------------------------------------
// Copies the items of one list of the appended plan to the output. Anchored nodes outside the items that
// the items refer to are kept as events while the text is read up to the list; an alias to one that is
// not in the output yet writes the node itself there (the whole-tree merge cloned it the same way).

class ListCopy final : public YAML::EventHandler {
  public:
    ListCopy(int list, const AppendedFacts& facts, Output& out)
        : list_(list), needs_(facts.list(list).needs), out_(out) {
        if (facts.list(list).any_needs) {
            kept_.resize(facts.anchors);
            replaying_.assign(facts.anchors, false);
        }
    }

    void OnDocumentStart(const YAML::Mark&) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, anchor_t anchor) override {
        handle({Kind::Null, Style::Default, anchor, {}, {}});
        walk_.leaf(nullptr, false);
    }
    void OnAlias(const YAML::Mark&, anchor_t anchor) override {
        const Slot s = walk_.slot();
        if (s.place == Place::List && s.list == list_) {
            replay(anchor, true);
            throw ListCopied{};
        }
        handle({Kind::Alias, Style::Default, anchor, {}, {}});
        walk_.leaf(nullptr, true);
    }
    void OnScalar(const YAML::Mark&, const std::string& tag, anchor_t anchor,
                  const std::string& value) override {
        const Slot s = walk_.slot();
        if (copying(s)) {
            out_.write.scalar(tag, out_.define(anchor), value);
        } else {
            handle({Kind::Scalar, Style::Default, anchor, tag, value});
        }
        walk_.leaf(&value, false);
    }
    void OnSequenceStart(const YAML::Mark&, const std::string& tag, anchor_t anchor, Style style) override {
        handle({Kind::SeqStart, style, anchor, tag, {}});
        walk_.open(false);
    }
    void OnSequenceEnd() override {
        close({Kind::SeqEnd, Style::Default, 0, {}, {}});
        walk_.close();
    }
    void OnMapStart(const YAML::Mark&, const std::string& tag, anchor_t anchor, Style style) override {
        handle({Kind::MapStart, style, anchor, tag, {}});
        walk_.open(true);
    }
    void OnMapEnd() override {
        close({Kind::MapEnd, Style::Default, 0, {}, {}});
        walk_.close();
    }

  private:
    enum class Kind : unsigned char { Null, Alias, Scalar, SeqStart, SeqEnd, MapStart, MapEnd };
    struct Event {
        Kind kind;
        Style style;
        anchor_t anchor;
        std::string tag, value;
    };
    struct Range {
        std::size_t begin = 0, end = 0;
    };
    struct Keeping {
        anchor_t anchor;
        std::size_t begin, depth;
    };
    bool copying(const Slot& s) const { return s.place == Place::Item && s.list == list_; }
    bool needed(anchor_t a) const { return a != 0 && a <= needs_.size() && needs_[a - 1]; }

    /// A node's first (or only) event.
    void handle(Event&& e) {
        const Slot s = walk_.slot();
        if (copying(s)) {
            put(e);
            return;
        }
        if (s.place == Place::List && s.list == list_) {
            if (e.kind != Kind::SeqStart) {
                throw ListCopied{};  // not a list: nothing to copy
            }
            return;
        }
        const bool opens = e.kind == Kind::SeqStart || e.kind == Kind::MapStart;
        const anchor_t anchor = e.kind == Kind::Alias ? 0 : e.anchor;  // an alias's is its target's
        if (!needed(anchor) && keeping_.empty()) {
            return;
        }
        log_.push_back(std::move(e));
        if (!needed(anchor)) {
            return;
        }
        if (opens) {
            keeping_.push_back({anchor, log_.size() - 1, walk_.depth() + 1});
        } else {
            kept_[anchor - 1] = {log_.size() - 1, log_.size()};
        }
    }
    /// A collection's end event.
    void close(Event&& e) {
        const Slot s = walk_.open_slot();
        if (copying(s)) {
            put(e);
            return;
        }
        if (s.place == Place::List && s.list == list_) {
            throw ListCopied{};
        }
        if (keeping_.empty()) {
            return;
        }
        log_.push_back(std::move(e));
        if (keeping_.back().depth == walk_.depth()) {
            kept_[keeping_.back().anchor - 1] = {keeping_.back().begin, log_.size()};
            keeping_.pop_back();
        }
    }

    void put(const Event& e) {
        auto& w = out_.write;
        switch (e.kind) {
            case Kind::Null:
                w.null(out_.define(e.anchor));
                break;
            case Kind::Alias:
                if (out_.written(e.anchor)) {
                    w.alias(Output::appended(e.anchor));
                } else {
                    replay(e.anchor, false);
                }
                break;
            case Kind::Scalar:
                w.scalar(e.tag, out_.define(e.anchor), e.value);
                break;
            case Kind::SeqStart:
            case Kind::MapStart:
                w.begin(e.kind == Kind::MapStart, e.tag, out_.define(e.anchor), e.style);
                break;
            case Kind::SeqEnd:
            case Kind::MapEnd:
                w.end();
                break;
        }
    }
    /// Writes the kept node `a` (only its items: the list key's value was an alias to it).
    void replay(anchor_t a, bool items_only) {
        // Not kept: it encloses the list being copied (an alias to an ancestor). Also guards a list given as
        // an alias to itself from recursing.
        if (a == 0 || a > kept_.size() || kept_[a - 1].end == 0 || replaying_[a - 1]) {
            throw NeedsWholeTree{};
        }
        Range r = kept_[a - 1];
        if (items_only) {
            if (log_[r.begin].kind != Kind::SeqStart) {
                return;
            }
            ++r.begin;
            --r.end;
        }
        replaying_[a - 1] = true;
        for (std::size_t i = r.begin; i < r.end; ++i) {
            put(log_[i]);
        }
        replaying_[a - 1] = false;
    }

    int list_;
    const std::vector<bool>& needs_;
    Output& out_;
    PlanWalker walk_;
    std::vector<Event> log_;  // events of the kept nodes, in document order
    std::vector<Range> kept_;
    std::vector<bool> replaying_;
    std::vector<Keeping> keeping_;
};

// ------------------------------------------------------------------------------------------------------
// The running plan, written out as it is read, with the appended lists copied in where its lists end.

class RunningMerge final : public YAML::EventHandler {
  public:
    RunningMerge(std::string_view appended, const AppendedFacts* facts, Output& out)
        : appended_(appended), facts_(facts), out_(out) {}

    bool plan_is_map() const { return walk_.plan_is_map(); }
    bool root_scalar = false;
    YAML::Mark root_mark = YAML::Mark::null_mark();
    bool pushback = false;  // a list to append to is neither a list nor null

    void OnDocumentStart(const YAML::Mark&) override {}
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, anchor_t anchor) override {
        const Slot s = walk_.slot();
        if (s.place == Place::List && adds(s.list)) {
            // A null list becomes the appended one, keeping its anchor: the whole-tree merge replaced the
            // node's content, which its aliases shared.
            out_.write.begin(false, "", Output::running(anchor), Style::Default);
            copy_items(s.list);
            out_.write.end();
        } else {
            out_.write.null(Output::running(anchor));
        }
        walk_.leaf(nullptr, false);
    }
    void OnAlias(const YAML::Mark&, anchor_t anchor) override {
        // Appending to a list given as an alias appends to the anchored node, which was written earlier.
        if (const Slot s = walk_.slot(); s.place == Place::List && adds(s.list)) {
            throw NeedsWholeTree{};
        }
        out_.write.alias(Output::running(anchor));
        walk_.leaf(nullptr, true);
    }
    void OnScalar(const YAML::Mark& mark, const std::string& tag, anchor_t anchor,
                  const std::string& value) override {
        const Slot s = walk_.slot();
        if (s.place == Place::Root) {
            root_scalar = true;
            root_mark = mark;
        }
        if (s.place == Place::List && has_items(s.list)) {
            pushback = true;
        }
        out_.write.scalar(tag, Output::running(anchor), value);
        walk_.leaf(&value, false);
    }
    void OnSequenceStart(const YAML::Mark&, const std::string& tag, anchor_t anchor, Style style) override {
        out_.write.begin(false, tag, Output::running(anchor), style);
        walk_.open(false);
    }
    void OnSequenceEnd() override {
        if (const Slot s = walk_.open_slot(); s.place == Place::List) {
            copy_items(s.list);
        }
        out_.write.end();
        walk_.close();
    }
    void OnMapStart(const YAML::Mark&, const std::string& tag, anchor_t anchor, Style style) override {
        if (const Slot s = walk_.slot(); s.place == Place::List && has_items(s.list)) {
            pushback = true;
        }
        out_.write.begin(true, tag, Output::running(anchor), style);
        walk_.open(true);
    }
    void OnMapEnd() override {
        if (walk_.open_slot().place == Place::Plan) {
            for (std::size_t k = 0; k < kLists.size(); ++k) {
                const int list = static_cast<int>(k);
                if (walk_.has_list(list) || !adds(list)) {
                    continue;
                }
                out_.write.scalar("", 0, std::string(kLists[k]));
                out_.write.begin(false, "", 0, Style::Default);
                copy_items(list);
                out_.write.end();
            }
        }
        out_.write.end();
        walk_.close();
    }

  private:
    bool adds(int k) const { return facts_ != nullptr && facts_->adds(k); }
    bool has_items(int k) const { return facts_ != nullptr && facts_->has_items(k); }

    void copy_items(int k) {
        if (!has_items(k)) {
            return;
        }
        ListCopy copy(k, *facts_, out_);
        TextStream in(appended_);
        YAML::Parser parser(in);
        try {
            parser.HandleNextDocument(copy);
        } catch (const ListCopied&) {
        }
    }

    std::string_view appended_;
    const AppendedFacts* facts_;
    Output& out_;
    PlanWalker walk_;
};

/// One streaming merge into `capacity` bytes; false when the text did not fit (`needed` is then its size).
/// `usable` is null when the appended plan cannot be merged: the running plan is then only read, for the
/// errors that come first.
bool stream_merge(std::string_view running, std::string_view appended, const AppendedFacts& facts,
                  const AppendedFacts* usable, const std::string& appended_error, std::size_t capacity,
                  MergedPlan& out, std::size_t& needed) {
    TextSink sink(capacity);
    bool good = false;
    std::string emitter_error;
    {
        std::ostream os(&sink);
        YAML::Emitter emitter(os);
        Output output(emitter, usable != nullptr ? usable->anchors : 0);
        RunningMerge merge(appended, usable, output);
        {
            TextStream in(running);
            YAML::Parser parser(in);
            // Its syntax errors first: the whole-tree merge loaded the running plan first.
            parser.HandleNextDocument(merge);
        }
        if (!appended_error.empty()) {
            out.error = "cannot merge the plans: " + appended_error;
            return true;
        }
        // Subscripting a scalar document for its plan threw, the running plan's first.
        if (merge.root_scalar) {
            throw YAML::BadSubscript(merge.root_mark, std::string("plan"));
        }
        if (facts.root_scalar) {
            throw YAML::BadSubscript(facts.root_mark, std::string("plan"));
        }
        if (merge.plan_is_map() && !facts.has_plan) {
            throw YAML::InvalidNode("plan");  // what yaml-cpp's const lookup of a missing key gave
        }
        if (!merge.plan_is_map() || !facts.plan_is_map) {
            out.error = "both plans need a 'plan' mapping";
            return true;
        }
        if (merge.pushback) {
            throw YAML::BadPushback();
        }
        good = emitter.good();
        if (!good) {
            emitter_error = emitter.GetLastError();
        }
    }
    if (!good) {
        out.error = "cannot write the merged plan: " + emitter_error;
        return true;
    }
    if (sink.overflowed()) {
        needed = sink.size() + 1;
        return false;
    }
    std::string text = sink.take();
    text.push_back('\n');
    // Reserved for a merged text as long as both inputs; give back a large excess (comments, indentation
    // that the emitter writes shorter). The copy is smaller than what the parser held.
    if (text.size() < text.capacity() / 2) {
        text.shrink_to_fit();
    }
    out.text = std::move(text);
    return true;
}

}  // namespace merge
}  // namespace

MergedPlan append_plan_text(std::string_view running, std::string_view appended) {
    using namespace merge;
    MergedPlan out;
    try {
        std::optional<AppendedFacts> facts;
        std::string appended_error;
        try {
            FactsReader reader;
            TextStream in(appended);
            YAML::Parser parser(in);
            parser.HandleNextDocument(reader);
            facts = reader.finish();
        } catch (const YAML::Exception& e) {
            // Reported after the running plan's own syntax errors, as before.
            appended_error = e.what();
        }
        if (!facts) {
            facts.emplace();
        }
        const AppendedFacts* usable =
            appended_error.empty() && !facts->root_scalar && facts->plan_is_map ? &*facts : nullptr;
        // A merged text is about as long as both texts (the emitter writes what it reads much as a plan is
        // usually written); when it is longer, the second pass knows its exact size.
        std::size_t capacity = running.size() + appended.size() + 64;
        if (!stream_merge(running, appended, *facts, usable, appended_error, capacity, out, capacity) &&
            !stream_merge(running, appended, *facts, usable, appended_error, capacity, out, capacity)) {
            throw NeedsWholeTree{};  // the same text came out longer twice: not expected, but not fatal
        }
    } catch (const NeedsWholeTree&) {
        // Layouts merged as whole trees, each detected where it is met: a running list that gets items and
        // is itself an alias (the items belong in the anchored node, written before); `plan:` given as an
        // alias, or an alias used as a key of the document or of the plan, in either text; an appended item
        // referring to a node that encloses its own list. An alias from the appended items to any other
        // node outside them (home, geofence, another list's item, a list given as an alias) streams.
        return append_plan_text_as_trees(running, appended);
    } catch (const YAML::Exception& e) {
        out.text.reset();
        out.error = std::string("cannot merge the plans: ") + e.what();
    }
    return out;
}

}  // namespace airseg::flightplan
