#pragma once
// yaml-cpp's scanner keeps every indentation marker it opened until the parser is destroyed: about 40 bytes
// for each element of a block list ("- waypoint: ..." opens one), as much as the plan keeps per element. A
// long plan's main list is therefore cut out of the text and read in batches, each by a parser of its own,
// while the rest of the document is read with "[]" where the list was.
//
// The cut is found by looking at the text's lines, for the usual layout only (a top-level "plan:" mapping
// whose "elements:" key holds a block list). A line at the list's column starting with "- " is an item's
// first line unless it is inside a flow collection, and then the batch before it ends with that collection
// open, which its parser refuses: the loader then reads the document unsplit. Lists with quotes (yaml-cpp
// ends an unterminated quoted scalar quietly where a batch ends), anchors or aliases or tabs in indentation,
// and texts with carriage returns, other control characters or malformed UTF-8 are left alone.
#include <cstddef>
#include <optional>
#include <streambuf>
#include <string_view>
#include <vector>

#include <yaml-cpp/mark.h>

namespace airseg::flightplan {

struct ListSplice {
    /// A run of whole lines holding whole items, read by one parser.
    struct Batch {
        std::size_t begin = 0;  // offset of its first line
        std::size_t end = 0;
        int first_line = 0;  // 0-based, as yaml-cpp counts
        /// Where the whole text's next token after the batch is. A mark at the batch's end (a null or a
        /// collection's end takes the next token's mark) is moved there, as the unsplit text would give it,
        /// unless the batch ends the text: its parser meets the same end, with the same indentation open.
        YAML::Mark after;
        bool ends_text = false;  // nothing but comments after it: read to the text's end, as it is
    };
    static constexpr std::string_view kStandIn = " []";

    std::size_t cut_begin = 0;  // just after "elements:"
    std::size_t cut_end = 0;    // the line break after the list's last line (or the end of the text)
    int cut_lines = 0;          // line breaks in [cut_begin, cut_end)
    std::vector<Batch> batches;

    /// A mark in the text with the list replaced by kStandIn, as a mark in the original text.
    YAML::Mark original(YAML::Mark mark) const;
};

/// The plan's main list, in batches of up to `items_per_batch` items; none when the layout is not the usual
/// one or the list is too short to be worth it.
std::optional<ListSplice> find_list_splice(std::string_view text, std::size_t items_per_batch);

/// Pieces of text read one after the other, where they lie (none is copied).
class PiecesBuffer : public std::streambuf {
  public:
    PiecesBuffer(std::string_view a, std::string_view b, std::string_view c = {}) : pieces_{a, b, c} {}

  protected:
    int_type underflow() override;

  private:
    std::string_view pieces_[3];
    std::size_t next_ = 0;
};

/// The text with the list replaced by ListSplice::kStandIn.
class SplicedBuffer : public PiecesBuffer {
  public:
    SplicedBuffer(std::string_view text, const ListSplice& splice)
        : PiecesBuffer(text.substr(0, splice.cut_begin), ListSplice::kStandIn, text.substr(splice.cut_end)) {}
};

/// A batch's text, then a comment line unless the batch ends the text: yaml-cpp is more lenient at the very
/// end of a text than before a following line (a plain scalar ending a mapping there is taken as a key).
class BatchBuffer : public PiecesBuffer {
  public:
    BatchBuffer(std::string_view text, const ListSplice::Batch& batch)
        : PiecesBuffer(text.substr(batch.begin, batch.end - batch.begin),
                       batch.ends_text                                          ? ""
                       : batch.end > batch.begin && text[batch.end - 1] == '\n' ? "#\n"
                                                                                : "\n#\n") {}
};

}  // namespace airseg::flightplan
