#include "services/flightplan/list_splice.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>

#include "base/utf8.hpp"

namespace airseg::flightplan {

namespace {

struct Line {
    std::size_t begin = 0;
    std::size_t end = 0;  // its line break, or the end of the text
    int number = 0;
    std::size_t indent = 0;
    bool content = false;  // not blank, not only a comment
    bool tab = false;      // a tab in its indentation
};

class Lines {
  public:
    explicit Lines(std::string_view text) : text_(text) {}

    bool next(Line& line) {
        if (at_ >= text_.size()) {
            return false;
        }
        line.begin = at_;
        const std::size_t brk = text_.find('\n', at_);
        line.end = brk == std::string_view::npos ? text_.size() : brk;
        line.number = number_++;
        at_ = brk == std::string_view::npos ? text_.size() : brk + 1;
        const std::string_view s = text_.substr(line.begin, line.end - line.begin);
        line.indent = std::min(s.find_first_not_of(' '), s.size());
        const std::size_t first = s.find_first_not_of(" \t");
        const bool blank = first == std::string_view::npos || s[first] == '#';
        line.content = !blank;
        line.tab = !blank && first != line.indent;  // YAML refuses tabs in indentation
        return true;
    }

  private:
    std::string_view text_;
    std::size_t at_ = 0;
    int number_ = 0;
};

/// Only spaces and a comment after `from` on the line.
bool rest_is_empty(std::string_view line, std::size_t from) {
    const std::size_t next = line.find_first_not_of(' ', from);
    return next == std::string_view::npos || (line[next] == '#' && next > from);
}

/// `key:` alone on its line at its indentation (a comment may follow).
bool is_bare_key(std::string_view line, std::size_t indent, std::string_view key) {
    const std::string_view s = line.substr(indent);
    return s.size() > key.size() && s.substr(0, key.size()) == key && s[key.size()] == ':' &&
           rest_is_empty(line, indent + key.size() + 1);
}

/// "- key:" with a plain key: the first line of a mapping item, as every plan element is. yaml-cpp runs a
/// plain scalar item on into a following "- " line, so a list with other items is read unsplit.
bool is_mapping_item(std::string_view line, std::size_t indent) {
    const std::size_t key = indent + 2;
    std::size_t end = key;
    while (end < line.size() && (std::isalnum(static_cast<unsigned char>(line[end])) != 0 ||
                                 line[end] == '_' || line[end] == '-')) {
        ++end;
    }
    return end > key && end < line.size() && line[end] == ':' &&
           (end + 1 == line.size() || line[end + 1] == ' ');
}

/// A line that is only a plain scalar, without a ": " or a final ':' (not "key: value", not a list entry, not
/// flow or quoted text). Where a mapping's key belongs, yaml-cpp runs such a line on into the next line, even
/// a "- " line at the list's column; elsewhere it is rare in a plan (a multi-line plain scalar, a block
/// scalar's text, the end of a flow collection written over lines). Lists with one are read unsplit.
bool bare_plain_line(std::string_view text) {
    if (text.empty() || text.rfind("- ", 0) == 0 || text == "-" ||
        std::string_view("{}[],\"'#&*!|>%@`").find(text[0]) != std::string_view::npos) {
        return false;
    }
    text = text.substr(0, text.find(" #"));  // a comment
    while (!text.empty() && text.back() == ' ') {
        text.remove_suffix(1);
    }
    return text.find(": ") == std::string_view::npos && text.back() != ':';  // no mapping indicator
}

bool is_item(std::string_view line, std::size_t indent) {
    return line.size() > indent && line[indent] == '-' &&
           (line.size() == indent + 1 || line[indent + 1] == ' ');
}

/// Printable text: tabs, line feeds, printable ASCII and well-formed UTF-8 only. yaml-cpp decodes other bytes
/// (malformed UTF-8, controls) in ways that depend on where they fall in its read buffer, so a batch could
/// read them otherwise than the whole text does.
bool plain_text(std::string_view text) {
    for (std::size_t i = 0; i < text.size();) {
        const auto c = utf8_next(text, i);
        if (!c || (is_control(*c) && *c != '\n' && *c != '\t') || *c == 0xfeff) {
            return false;
        }
    }
    return true;
}

}  // namespace

YAML::Mark ListSplice::original(YAML::Mark mark) const {
    if (mark.is_null() || static_cast<std::size_t>(mark.pos) < cut_begin + kStandIn.size()) {
        return mark;
    }
    mark.pos += static_cast<int>(cut_end - cut_begin - kStandIn.size());
    mark.line += cut_lines;
    return mark;
}

std::optional<ListSplice> find_list_splice(std::string_view text, std::size_t items_per_batch) {
    if (items_per_batch == 0 || !plain_text(text)) {
        return std::nullopt;
    }
    Lines lines(text);
    Line line;
    auto of = [&](const Line& l) { return text.substr(l.begin, l.end - l.begin); };
    auto next_content = [&]() {
        while (lines.next(line)) {
            if (line.tab) {
                return false;
            }
            if (line.content) {
                return true;
            }
        }
        return false;
    };

    // The document's first key is "plan", holding a block mapping.
    if (!next_content()) {
        return std::nullopt;
    }
    if (line.indent == 0 && of(line).substr(0, 3) == "---" && rest_is_empty(of(line), 3) && !next_content()) {
        return std::nullopt;
    }
    if (line.indent != 0 || !is_bare_key(of(line), 0, "plan") || !next_content() || line.indent == 0) {
        return std::nullopt;
    }
    // Its first "elements" key, holding a block list.
    const std::size_t body = line.indent;
    while (!(line.indent == body && is_bare_key(of(line), body, "elements"))) {
        if (!next_content() || line.indent < body) {
            return std::nullopt;
        }
    }
    ListSplice splice;
    splice.cut_begin = line.begin + body + std::string_view("elements:").size();
    if (!next_content() || line.indent < body || !is_item(of(line), line.indent)) {
        return std::nullopt;
    }
    const std::size_t column = line.indent;
    std::vector<Line> starts;  // of the batches
    std::size_t items = 0;
    std::size_t last_end = line.end;
    bool followed = false;  // by a content line after the list
    do {
        const std::string_view s = of(line);
        if (line.indent < column || (line.indent == column && !is_item(s, column))) {
            followed = true;
            break;
        }
        if ((line.indent == column && !is_mapping_item(s, column)) ||
            bare_plain_line(s.substr(line.indent))) {
            return std::nullopt;
        }
        if (line.indent == column && items++ % items_per_batch == 0) {
            starts.push_back(line);
        }
        last_end = line.end;
    } while (next_content());
    // What follows the list is the plan's next key or the document's; anything else reads differently once
    // the list is "[]".
    if (line.tab || (followed && line.indent > body)) {
        return std::nullopt;
    }
    const std::string_view cut = text.substr(splice.cut_begin, last_end - splice.cut_begin);
    // An anchor or alias would span batches (a parser knows its own anchors only). A quoted scalar may run
    // over an item's line, and yaml-cpp ends an unterminated one quietly at the end of a batch. The
    // characters are looked for anywhere, in comments too: then the list is read unsplit.
    if (items <= items_per_batch || cut.find_first_of("&*\"'") != std::string_view::npos) {
        return std::nullopt;
    }
    splice.cut_end = last_end;
    splice.cut_lines = static_cast<int>(std::count(cut.begin(), cut.end(), '\n'));
    auto mark_at = [](std::size_t pos, int line_number, std::size_t column) {
        YAML::Mark mark;
        mark.pos = static_cast<int>(pos);
        mark.line = line_number;
        mark.column = static_cast<int>(column);
        return mark;
    };
    for (std::size_t i = 0; i < starts.size(); ++i) {
        ListSplice::Batch batch;
        batch.begin = starts[i].begin;
        batch.end = i + 1 < starts.size() ? starts[i + 1].begin : followed ? last_end + 1 : text.size();
        batch.ends_text = i + 1 == starts.size() && !followed;
        batch.first_line = starts[i].number;
        if (i + 1 < starts.size()) {
            batch.after = mark_at(starts[i + 1].begin + column, starts[i + 1].number, column);
        } else if (followed) {
            batch.after = mark_at(line.begin + line.indent, line.number, line.indent);
        }  // else the batch ends the text, and its own marks are kept
        splice.batches.push_back(batch);
    }
    return splice;
}

PiecesBuffer::int_type PiecesBuffer::underflow() {
    while (next_ < 3) {
        const std::string_view piece = pieces_[next_++];
        if (!piece.empty()) {
            char* p = const_cast<char*>(piece.data());  // get area only: never written
            setg(p, p, p + piece.size());
            return traits_type::to_int_type(*p);
        }
    }
    return traits_type::eof();
}

}  // namespace airseg::flightplan
