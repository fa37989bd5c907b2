#pragma once
// A test reference, not a product parser: a compact model of the receive path of the official MAVLink C
// library (c_library_v2, mavlink_helpers.h), mavlink_parse_char() over mavlink_frame_char_buffer(), built
// without MAVLINK_CHECK_MESSAGE_LENGTH unless asked, with no signing set up (status->signing == NULL) and
// MAVLINK_MAX_PAYLOAD_LEN 255, as a ground station or companion computer built against the generated
// headers would run it. Its message table (mavlink_get_msg_entry: id, CRC_EXTRA, minimum and maximum
// length) is whatever the test passes in.
//
// What the modelled state machine does, byte by byte (MAVLINK_PARSE_STATE_*):
//  - IDLE: waits for 0xFD (MAVLink 2) or 0xFE (MAVLink 1); every other byte is skipped.
//  - GOT_STX: takes the length byte (never rejected with a 255-byte payload buffer).
//  - GOT_LENGTH (v2 only): the incompatibility flags; a flag other than SIGNED is a parse error and the state
//    goes back to IDLE at once (the flag byte is consumed, not rescanned as a start byte).
//  - compatibility flags (v2), sequence, sysid, compid, message id (1 byte v1, 3 bytes v2). With
//    MAVLINK_CHECK_MESSAGE_LENGTH a length outside the id's [min, max] is a parse error (an id missing from
//    the table has min = max = 0), back to IDLE.
//  - the payload, then CRC1: an id missing from the table, or a first checksum byte that differs, makes the
//    frame a bad one (GOT_BAD_CRC1); CRC2 decides MAVLINK_FRAMING_OK or MAVLINK_FRAMING_BAD_CRC.
//  - a frame with the SIGNED flag then waits for 13 signature bytes (not checked without signing);
//    mavlink_parse_char() turns BAD_CRC into a parse error and IDLE at once, so after a bad signed frame
//    the signature bytes are scanned for start bytes.
// Bytes of a frame that failed are never looked at again: the C library does not rescan.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "services/autopilot/mavlink/crc.hpp"

namespace airseg::mavlink::reference {

struct MsgEntry {  // mavlink_msg_entry_t, the fields the parser reads
    std::uint32_t msgid;
    std::uint8_t crc_extra;
    std::uint8_t min_msg_len;
    std::uint8_t max_msg_len;
};

struct Message {  // mavlink_message_t, as far as a frame's bytes go
    std::uint8_t magic = 0;
    std::uint8_t len = 0;
    std::uint8_t incompat_flags = 0;
    std::uint8_t compat_flags = 0;
    std::uint8_t seq = 0;
    std::uint8_t sysid = 0;
    std::uint8_t compid = 0;
    std::uint32_t msgid = 0;
    std::array<std::uint8_t, 255> payload{};
    std::array<std::uint8_t, 2> ck{};
    std::array<std::uint8_t, 13> signature{};
};

class ReferenceParser {
  public:
    /// `table` sorted by msgid, as MAVLINK_MESSAGE_CRCS is.
    explicit ReferenceParser(std::vector<MsgEntry> table, bool check_message_length = false)
        : table_(std::move(table)), check_length_(check_message_length) {}

    /// mavlink_parse_char(): true when `c` completes a frame whose checksum matches; message() holds it.
    bool parse_char(std::uint8_t c) {
        const Framing r = frame_char(c);
        if (r == Framing::BadCrc) {
            ++parse_errors_;
            state_ = State::Idle;
            return false;
        }
        return r == Framing::Ok;
    }

    const Message& message() const { return msg_; }
    std::uint64_t parse_errors() const { return parse_errors_; }

  private:
    enum class State : std::uint8_t {
        Idle,
        GotStx,
        GotLength,
        GotIncompatFlags,
        GotCompatFlags,
        GotSeq,
        GotSysid,
        GotCompid,
        GotMsgid1,
        GotMsgid2,
        GotMsgid3,  // receiving the payload
        GotPayload,
        GotCrc1,
        GotBadCrc1,
        SignatureWait,
    };
    enum class Framing : std::uint8_t { Incomplete, Ok, BadCrc };
    static constexpr std::uint8_t kStxV2 = 0xFD;
    static constexpr std::uint8_t kStxV1 = 0xFE;
    static constexpr std::uint8_t kIflagSigned = 0x01;  // MAVLINK_IFLAG_MASK is this one flag

    const MsgEntry* get_msg_entry(std::uint32_t msgid) const {
        const auto it = std::lower_bound(table_.begin(), table_.end(), msgid,
                                         [](const MsgEntry& e, std::uint32_t id) { return e.msgid < id; });
        return it != table_.end() && it->msgid == msgid ? &*it : nullptr;
    }
    bool length_rejected() const {  // MAVLINK_CHECK_MESSAGE_LENGTH
        const MsgEntry* e = get_msg_entry(msg_.msgid);
        const std::uint8_t min = e != nullptr ? e->min_msg_len : 0;
        const std::uint8_t max = e != nullptr ? e->max_msg_len : 0;
        return check_length_ && (msg_.len < min || msg_.len > max);
    }
    void update(std::uint8_t c) { crc_.add(c); }

    // mavlink_frame_char_buffer(), the states above; returns msg_received.
    Framing frame_char(std::uint8_t c) {
        switch (state_) {
            case State::Idle:
                if (c == kStxV2 || c == kStxV1) {
                    state_ = State::GotStx;
                    msg_.len = 0;
                    msg_.magic = c;
                    v1_ = c == kStxV1;
                    crc_ = Crc16{};
                }
                break;
            case State::GotStx:
                msg_.len = c;
                packet_idx_ = 0;
                update(c);
                if (v1_) {
                    msg_.incompat_flags = 0;
                    msg_.compat_flags = 0;
                    state_ = State::GotCompatFlags;
                } else {
                    state_ = State::GotLength;
                }
                break;
            case State::GotLength:
                msg_.incompat_flags = c;
                if ((c & ~kIflagSigned) != 0) {
                    ++parse_errors_;
                    state_ = State::Idle;
                    break;
                }
                update(c);
                state_ = State::GotIncompatFlags;
                break;
            case State::GotIncompatFlags:
                msg_.compat_flags = c;
                update(c);
                state_ = State::GotCompatFlags;
                break;
            case State::GotCompatFlags:
                msg_.seq = c;
                update(c);
                state_ = State::GotSeq;
                break;
            case State::GotSeq:
                msg_.sysid = c;
                update(c);
                state_ = State::GotSysid;
                break;
            case State::GotSysid:
                msg_.compid = c;
                update(c);
                state_ = State::GotCompid;
                break;
            case State::GotCompid:
                msg_.msgid = c;
                update(c);
                if (!v1_) {
                    state_ = State::GotMsgid1;
                    break;
                }
                state_ = msg_.len > 0 ? State::GotMsgid3 : State::GotPayload;
                if (length_rejected()) {
                    ++parse_errors_;
                    state_ = State::Idle;
                }
                break;
            case State::GotMsgid1:
                msg_.msgid |= std::uint32_t{c} << 8;
                update(c);
                state_ = State::GotMsgid2;
                break;
            case State::GotMsgid2:
                msg_.msgid |= std::uint32_t{c} << 16;
                update(c);
                state_ = msg_.len > 0 ? State::GotMsgid3 : State::GotPayload;
                if (length_rejected()) {
                    ++parse_errors_;
                    state_ = State::Idle;
                }
                break;
            case State::GotMsgid3:
                msg_.payload[packet_idx_++] = c;
                update(c);
                if (packet_idx_ == msg_.len) {
                    state_ = State::GotPayload;
                }
                break;
            case State::GotPayload: {
                const MsgEntry* e = get_msg_entry(msg_.msgid);
                if (e == nullptr) {
                    state_ = State::GotBadCrc1;  // not in the CRC_EXTRA table
                } else {
                    update(e->crc_extra);
                    state_ = c == (crc_.value() & 0xFF) ? State::GotCrc1 : State::GotBadCrc1;
                    // (the library zero-fills the payload up to max_msg_len here)
                    std::fill(msg_.payload.begin() + packet_idx_, msg_.payload.end(), std::uint8_t{0});
                }
                msg_.ck[0] = c;
                break;
            }
            case State::GotCrc1:
            case State::GotBadCrc1: {
                const bool ok = state_ == State::GotCrc1 && c == (crc_.value() >> 8);
                msg_.ck[1] = c;
                if ((msg_.incompat_flags & kIflagSigned) != 0 && ok) {
                    state_ = State::SignatureWait;
                    signature_wait_ = 13;
                    return Framing::Incomplete;
                }
                // A bad signed frame would wait for its signature in mavlink_frame_char(), but
                // mavlink_parse_char() resets to IDLE on BAD_CRC straight away.
                state_ = State::Idle;
                return ok ? Framing::Ok : Framing::BadCrc;
            }
            case State::SignatureWait:
                msg_.signature[13 - signature_wait_] = c;
                if (--signature_wait_ == 0) {
                    state_ = State::Idle;
                    return Framing::Ok;  // no signing configured: mavlink_signature_check() is true
                }
                break;
        }
        return Framing::Incomplete;
    }

    std::vector<MsgEntry> table_;
    bool check_length_;
    State state_ = State::Idle;
    bool v1_ = false;  // MAVLINK_STATUS_FLAG_IN_MAVLINK1
    std::uint8_t packet_idx_ = 0;
    std::uint8_t signature_wait_ = 0;
    Crc16 crc_;
    Message msg_;
    std::uint64_t parse_errors_ = 0;
};

}  // namespace airseg::mavlink::reference
