#include "services/autopilot/mavlink/parser.hpp"

#include <algorithm>
#include <cstring>

#include "services/autopilot/mavlink/crc.hpp"
#include "services/autopilot/mavlink/wire.hpp"

namespace airseg::mavlink {
namespace {

bool is_magic(std::uint8_t b) {
    return b == kMagicV1 || b == kMagicV2;
}

std::size_t header_length(std::uint8_t magic) {
    return magic == kMagicV1 ? kHeaderLengthV1 : kHeaderLengthV2;
}

// Header fields of the candidate at the start of a buffer that holds at least its header.
struct Header {
    Version version;
    std::uint8_t payload_length;
    std::uint8_t incompat_flags;
    std::uint8_t compat_flags;
    std::uint8_t seq;
    std::uint8_t sysid;
    std::uint8_t compid;
    std::uint32_t msgid;
    std::size_t header_length;

    bool is_signed() const { return version == Version::V2 && (incompat_flags & kIncompatSigned) != 0; }
    bool unknown_flags() const { return (incompat_flags & ~kIncompatSigned) != 0; }
    // Up to the end of the checksum: all a frame with a known id needs to be verified.
    std::size_t checked_length() const { return header_length + payload_length + kChecksumLength; }
    std::size_t frame_length() const { return checked_length() + (is_signed() ? kSignatureLength : 0); }
};

// Length of the frame a start byte claims, from its first three bytes only (magic, payload length and, for
// MAVLink 2, the incompatibility flags).
std::size_t claimed_length(const std::uint8_t* p) {
    const bool is_signed = p[0] == kMagicV2 && (p[2] & kIncompatSigned) != 0;
    return header_length(p[0]) + p[1] + kChecksumLength + (is_signed ? kSignatureLength : 0);
}

Header read_header(const std::uint8_t* p) {
    if (p[0] == kMagicV1) {
        return Header{Version::V1, p[1], 0, 0, p[2], p[3], p[4], p[5], kHeaderLengthV1};
    }
    const std::uint32_t msgid = p[7] | (std::uint32_t{p[8]} << 8) | (std::uint32_t{p[9]} << 16);
    return Header{Version::V2, p[1], p[2], p[3], p[4], p[5], p[6], msgid, kHeaderLengthV2};
}

// Whether the frame with a known id at p (complete up to its checksum) has a matching checksum.
bool checksum_matches(const std::uint8_t* p, const Header& h, const MessageInfo& info) {
    Crc16 crc;
    crc.add(std::span<const std::uint8_t>(p + 1, h.header_length - 1 + h.payload_length));
    crc.add(info.crc_extra);
    return crc.value() == wire::get<std::uint16_t>(p + h.header_length + h.payload_length);
}

// Whether a candidate found inside another one has a length its message can have: a MAVLink 1 payload is
// exactly the base fields, a MAVLink 2 one at most all fields (trailing zeros truncated). A frame inside
// another is looked for among bytes that are not a frame start for certain, where a 16-bit checksum alone
// would match by chance once in 65,536 candidates with a declared id; a heartbeat-sized pattern in an
// undeclared message's payload is common enough for that to happen on a busy link.
bool plausible_inner(const Header& h, const MessageInfo& info) {
    return h.version == Version::V1 ? h.payload_length == info.base_length : h.payload_length <= info.length;
}

}  // namespace

const LinkStats* Parser::link(std::uint8_t sysid, std::uint8_t compid) const {
    for (const LinkStats& l : links()) {
        if (l.sysid == sysid && l.compid == compid) {
            return &l;
        }
    }
    return nullptr;
}

void Parser::push(std::span<const std::uint8_t> bytes, Sink sink) {
    // The common case of a small read (a UART gives a few bytes at a time): bytes that do not complete the
    // head and hold no start byte. Then there is nothing to judge, exactly as push_and_judge() would find
    // after looking: they are only kept.
    if (len_ + bytes.size() < append_limit_) {
        // Copied as checked: bytes past len_ are free, and push_and_judge() would copy the same ones there.
        std::uint8_t* out = buf_.data() + len_;
        std::size_t i = 0;
        for (; i < bytes.size() && !is_magic(bytes[i]); ++i) {
            out[i] = bytes[i];
        }
        if (i == bytes.size()) {
            len_ += i;
            scanned_ = len_;
            return;
        }
    }
    push_and_judge(bytes, sink);
    append_limit_ = append_limit();
}

void Parser::push_and_judge(std::span<const std::uint8_t> bytes, Sink sink) {
    std::size_t pos = 0;
    while (true) {
        if (len_ == 0 && signature_left_ == 0) {
            // Fast path between frames: skip noise in place, without copying it.
            const auto* start = bytes.data() + pos;
            const auto* end = bytes.data() + bytes.size();
            const auto* magic = std::find_if(start, end, is_magic);
            discard(static_cast<std::size_t>(magic - start));
            pos = static_cast<std::size_t>(magic - bytes.data());
            if (pos == bytes.size()) {
                return;
            }
            buf_[0] = bytes[pos++];
            len_ = 1;
            scanned_ = 1;  // the start byte itself is no inner start
        }
        if (head() != Head::Noise) {
            const std::size_t need = required_length();
            if (len_ < need) {
                const std::size_t n = std::min(need - len_, bytes.size() - pos);
                if (n > 0) {  // an empty span may carry a null pointer, which memcpy must not get
                    std::memcpy(buf_.data() + len_, bytes.data() + pos, n);
                }
                len_ += n;
                pos += n;
            }
            if (resync_inside_candidate(sink, need)) {
                continue;
            }
            if (len_ < need) {
                return;  // all bytes taken
            }
            if (required_length() != need) {
                continue;  // more of the candidate is known now: the required length changes
            }
        }
        step(sink, false);
    }
}

void Parser::finish(Sink sink) {
    while (len_ > 0 || signature_left_ > 0) {
        if (head() != Head::Noise && resync_inside_candidate(sink, required_length())) {
            continue;
        }
        step(sink, true);
    }
    append_limit_ = 0;
}

// Below how many bytes in the buffer push() may only append: while the head is a candidate whose header, or
// with a known id whose checksum, is incomplete and no start byte inside it is pending. 0 when not.
std::size_t Parser::append_limit() const {
    if (len_ == 0 || signature_left_ != 0 || inner_count_ != 0 || scanned_ != len_) {
        return 0;
    }
    if (head_cached_) {
        return head_cache_ == Head::Known ? head_checked_length_ : 0;
    }
    return is_magic(buf_[0]) ? header_length(buf_[0]) : 0;
}

Parser::Head Parser::head() const {
    if (signature_left_ > 0) {
        return Head::Signature;
    }
    if (head_cached_) {
        return head_cache_;
    }
    if (len_ == 0) {
        return Head::Noise;
    }
    if (!is_magic(buf_[0])) {
        head_cache_ = Head::Noise;
    } else if (len_ < header_length(buf_[0])) {
        return Head::Incomplete;  // looked at again as bytes arrive
    } else {
        const Header h = read_header(buf_.data());
        head_info_ = find_dialect_message(h.msgid);
        head_checked_length_ = h.checked_length();
        head_cache_ = head_info_ != nullptr ? Head::Known
                      : h.unknown_flags()   ? Head::Unacceptable
                                            : Head::Unknown;
    }
    head_cached_ = true;  // until the front of the buffer is dropped
    return head_cache_;
}

// Bytes of the head that nothing can verify: a signature, or a whole frame with an unknown message id.
std::size_t Parser::unverifiable_length(Head kind) const {
    switch (kind) {
        case Head::Signature:
            return signature_left_;
        case Head::Unknown:
            return read_header(buf_.data()).frame_length();
        default:
            return 0;
    }
}

// Bytes needed before the head can be judged:
//  - a frame with a known id: up to its checksum;
//  - a frame with an unknown id: the whole frame and one byte of look-ahead, which must be a start byte;
//    then, since its length byte cannot be trusted, also every candidate that starts inside it and could
//    turn out a verified frame (a known id and a plausible length), so that such a frame is never given up
//    for it;
//  - a signature (not verified, so a lost byte in it would otherwise eat the start byte of the next frame):
//    its 13 bytes and every candidate inside it that could turn out a verified frame;
//  - an unknown id with an unknown incompatibility flag: only its header (it is given up at once).
std::size_t Parser::required_length() const {
    const Head kind = head();
    switch (kind) {
        case Head::Noise:
            return 1;
        case Head::Signature:
            return pending_end(0, signature_left_, signature_left_);
        case Head::Incomplete:
        case Head::Unacceptable:
            return header_length(buf_[0]);
        case Head::Known:
            return head_checked_length_;
        case Head::Unknown: {
            const std::size_t length = unverifiable_length(kind);
            if (len_ <= length || !is_magic(buf_[length])) {
                return length + 1;
            }
            return pending_end(1, length, length + 1);
        }
    }
    return 1;
}

// The larger of `at_least` and the end of every candidate starting in [first, end) that could still turn
// out to be a verified frame: up to its header while the header is incomplete, up to its checksum when its
// id is known and its length plausible for it.
std::size_t Parser::pending_end(std::size_t first, std::size_t end, std::size_t at_least) const {
    std::size_t need = at_least;
    for (std::size_t k = first; k < std::min(end, len_); ++k) {
        if (!is_magic(buf_[k])) {
            continue;
        }
        const std::size_t header = header_length(buf_[k]);
        if (len_ - k < header) {
            need = std::max(need, k + header);
            continue;
        }
        const Header h = read_header(buf_.data() + k);
        const MessageInfo* info = find_dialect_message(h.msgid);
        if (info != nullptr && plausible_inner(h, *info)) {
            need = std::max(need, k + h.checked_length());
        }
    }
    return need;
}

// A frame that begins inside the head may be complete before the head can be judged: after a lost byte (or
// a stray start byte in noise) the head's length comes from the wrong byte, and waiting for it to fill
// would hold good frames back until unrelated later traffic arrives, on a quiet line for seconds. A
// complete frame with a known id, a plausible length and a matching checksum inside the head proves the
// head damaged: it is dropped up to that frame. Of such frames, the one that is complete first in the stream
// wins, and only if it is complete before the head can be judged (`need` bytes), exactly as if the stream
// came one byte at a time; so the outcome does not depend on how the stream is split, or on how many bytes
// are at hand.
//
// A head that cannot be verified (unknown id, signature) also loses to a verified frame complete at the
// moment it could be judged, and it waits for the candidates inside it (required_length()). But if a
// verified frame that starts after it is complete first, nothing inside it can be verified before that
// frame, which it does not overlap: the head stands.
//
// Each inner start byte is looked at once as it arrives (note_inner_starts) and then kept only while it
// can still begin a verified frame: its header incomplete, or its id known, its length plausible and its
// checksum not yet complete in time. Its checksum is computed once, when it is.
void Parser::note_inner_starts(std::size_t first) {
    scanned_ = std::max(scanned_, first);
    for (; scanned_ < len_; ++scanned_) {
        if (is_magic(buf_[scanned_])) {
            inner_at_[inner_count_] = static_cast<std::uint16_t>(scanned_);
            inner_end_[inner_count_] = 0;
            ++inner_count_;
        }
    }
}

bool Parser::resync_inside_candidate(Sink sink, std::size_t need) {
    const Head kind = head();
    const std::size_t unverifiable = unverifiable_length(kind);
    // Inner frames must be complete at or before this.
    const std::size_t limit = std::min(len_, unverifiable > 0 ? need : need - 1);
    note_inner_starts(kind == Head::Signature ? 0 : 1);
    bool found = false;
    std::size_t found_at = 0;
    std::size_t found_end = limit + 1;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < inner_count_; ++i) {
        const std::size_t k = inner_at_[i];
        std::size_t end = inner_end_[i];
        if (end == 0) {
            if (len_ - k >= header_length(buf_[k])) {
                const Header h = read_header(buf_.data() + k);
                const MessageInfo* info = find_dialect_message(h.msgid);
                if (info == nullptr || !plausible_inner(h, *info)) {
                    continue;  // can never be verified: dropped
                }
                end = k + h.checked_length();
            }
        }
        // Checked now if complete in time and before one already found (ties go to the earlier start);
        // one that fails its checksum is dropped.
        if (end != 0 && end < found_end) {
            const Header h = read_header(buf_.data() + k);
            if (!checksum_matches(buf_.data() + k, h, *find_dialect_message(h.msgid))) {
                continue;
            }
            found = true;
            found_at = k;
            found_end = end;
        }
        inner_at_[kept] = static_cast<std::uint16_t>(k);
        inner_end_[kept] = static_cast<std::uint16_t>(end);
        ++kept;
    }
    inner_count_ = kept;
    if (!found) {
        return false;
    }
    if (kind == Head::Signature) {
        // The signature ends where the frame found begins, or was complete before it.
        drop_front(std::min(found_at, signature_left_));
        signature_left_ = 0;
        return true;
    }
    if (unverifiable > 0 && found_at >= unverifiable) {
        accept(sink, unverifiable, nullptr);
        return true;
    }
    account_failed_starts(found_at);
    drop_front(found_at);
    return true;
}

// The bytes before the good frame at buf_[k] are dropped in one go. They are accounted as if each start byte
// among them had been judged on its own and failed, as step() and judge() do: it opens a damaged stretch of
// the length it claims unless one is already open, and every byte is discarded. The good frame then
// resolves a stretch still open as `truncated` (accept()). So a damaged frame that lies between an open
// stretch and the good frame counts as damaged, not as noise, whether or not the good frame was found early.
void Parser::account_failed_starts(std::size_t k) {
    std::size_t p = 0;
    while (p < k) {
        if (is_magic(buf_[p])) {
            // The claimed length needs only the length and flag bytes, which lie before the good frame.
            mark_damaged(claimed_length(buf_.data() + p), DamageKind::BadChecksum);
            discard(1);
            ++p;
            continue;
        }
        const auto* next = std::find_if(buf_.data() + p, buf_.data() + k, is_magic);
        const auto n = static_cast<std::size_t>(next - (buf_.data() + p));
        discard(n);
        p += n;
    }
}

void Parser::step(Sink sink, bool at_end) {
    const Head kind = head();
    if (kind == Head::Noise) {
        const auto magic =
            std::find_if(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(len_), is_magic);
        const auto n = static_cast<std::size_t>(magic - buf_.begin());
        discard(n);
        drop_front(n);
        return;
    }
    if (len_ >= required_length()) {
        judge(sink, kind);
        return;
    }
    if (!at_end) {
        return;
    }
    // The stream ended before the head could be judged.
    if (kind == Head::Signature) {
        drop_front(std::min(len_, signature_left_));
        signature_left_ = 0;
        return;
    }
    if (kind == Head::Unknown && len_ >= unverifiable_length(kind)) {
        // An unverifiable frame that nothing after it contradicts, and no verified frame inside it.
        accept(sink, unverifiable_length(kind), nullptr);
        return;
    }
    mark_damaged(len_, DamageKind::Truncated);
    discard(1);
    drop_front(1);
}

// The head with all the bytes it needs (required_length()), no verified frame found inside it.
void Parser::judge(Sink sink, Head kind) {
    if (kind == Head::Signature) {
        drop_front(signature_left_);
        signature_left_ = 0;
        return;
    }
    const Header h = read_header(buf_.data());
    if (kind == Head::Known) {
        const MessageInfo* info = head_info_;
        if (checksum_matches(buf_.data(), h, *info)) {
            accept(sink, h.checked_length(), info);
            return;
        }
    } else if (kind == Head::Unknown && is_magic(buf_[h.frame_length()])) {
        accept(sink, h.frame_length(), nullptr);
        return;
    }
    mark_damaged(h.frame_length(), DamageKind::BadChecksum);
    discard(1);
    drop_front(1);
}

// A frame that passed its checks (or, for an unknown id, was not contradicted by the bytes after it). A
// verified frame is taken up to its checksum; its signature, if it has one, follows as a head of its own.
void Parser::accept(Sink sink, std::size_t frame_length, const MessageInfo* info) {
    const Header h = read_header(buf_.data());
    resolve_damage_by_good_frame();
    track_sequence(h.sysid, h.compid, h.seq);
    const std::size_t signature = info != nullptr && h.is_signed() ? kSignatureLength : 0;
    if (h.unknown_flags()) {
        ++stats_.incompat_rejected;
        drop_front(frame_length);
        signature_left_ = signature;
        return;
    }
    deliver(sink, frame_length, info, signature);
}

void Parser::deliver(Sink sink, std::size_t frame_length, const MessageInfo* info, std::size_t signature) {
    const Header h = read_header(buf_.data());
    frame_.version = h.version;
    frame_.incompat_flags = h.incompat_flags;
    frame_.compat_flags = h.compat_flags;
    frame_.seq = h.seq;
    frame_.sysid = h.sysid;
    frame_.compid = h.compid;
    frame_.msgid = h.msgid;
    frame_.wire_length = h.payload_length;
    frame_.payload_length = info != nullptr ? std::max(h.payload_length, info->length) : h.payload_length;
    frame_.is_signed = h.is_signed();
    frame_.checksum_verified = info != nullptr;
    frame_.typed = info != nullptr && info->typed;
    // The payload stays zero beyond wire_length: only what the previous frames wrote there is cleared.
    std::memcpy(frame_.payload.data(), buf_.data() + h.header_length, h.payload_length);
    if (payload_dirty_ > h.payload_length) {
        std::memset(frame_.payload.data() + h.payload_length, 0, payload_dirty_ - h.payload_length);
    }
    payload_dirty_ = h.payload_length;
    if (info != nullptr) {
        ++stats_.frames_ok;
    } else {
        ++stats_.unknown_msgid;
    }
    if (frame_.is_signed) {
        ++stats_.signed_frames;
    }
    drop_front(frame_length);
    signature_left_ = signature;
    sink(frame_);
}

void Parser::track_sequence(std::uint8_t sysid, std::uint8_t compid, std::uint8_t seq) {
    ++frames_seen_;
    for (std::size_t i = 0; i < link_count_; ++i) {
        LinkStats& l = links_[i];
        if (l.sysid == sysid && l.compid == compid) {
            const auto gap = static_cast<std::uint8_t>(seq - l.last_seq - 1);
            l.lost += gap;
            stats_.seq_lost += gap;
            l.last_seq = seq;
            ++l.received;
            link_last_heard_[i] = frames_seen_;
            return;
        }
    }
    std::size_t slot = link_count_;
    if (link_count_ < kMaxLinks) {
        ++link_count_;
    } else {
        slot = static_cast<std::size_t>(std::min_element(link_last_heard_.begin(), link_last_heard_.end()) -
                                        link_last_heard_.begin());
    }
    links_[slot] = LinkStats{sysid, compid, seq, 1, 0};
    link_last_heard_[slot] = frames_seen_;
}

void Parser::mark_damaged(std::size_t span, DamageKind kind) {
    if (damaged_left_ == 0) {
        damaged_left_ = span;
        damage_kind_ = kind;
    }
}

void Parser::resolve_damage_by_good_frame() {
    if (damaged_left_ > 0) {
        ++stats_.truncated;
        damaged_left_ = 0;
    }
}

// Accounts for n bytes thrown away: inside a damaged frame they are part of it, outside they are noise.
void Parser::discard(std::size_t n) {
    const std::size_t in_damaged = std::min(n, damaged_left_);
    stats_.garbage_bytes += n - in_damaged;
    if (in_damaged > 0) {
        damaged_left_ -= in_damaged;
        if (damaged_left_ == 0) {
            ++(damage_kind_ == DamageKind::Truncated ? stats_.truncated : stats_.bad_checksum);
        }
    }
}

void Parser::drop_front(std::size_t n) {
    std::memmove(buf_.data(), buf_.data() + n, len_ - n);
    len_ -= n;
    inner_count_ = 0;
    scanned_ = 0;
    head_cached_ = false;
}

}  // namespace airseg::mavlink
