#pragma once
// The receiver of a 2.x-era ArduPilot board: mavlink_parse_char() of the MAVLink 1.0 C library the firmware
// was built with (include/mavlink/v1.0/mavlink_helpers.h), one byte at a time.
//
//  - Idle, it skips every byte but the MAVLink 1 start byte 0xFE. A MAVLink 2 frame (0xFD ...) is line
//    noise: its bytes are skipped, unless one of them is 0xFE, which starts a candidate that swallows the
//    bytes after it (possibly the start of the next good frame). Each 0xFD met while idle is counted:
//    normally one per MAVLink 2 frame that reached the board and was not understood (a 0xFD inside the frame,
//    as the message id of STATUSTEXT, 253, counts as well).
//  - It reads length, sequence, system, component, message id and payload, then checks the checksum with the
//    message's CRC_EXTRA from the firmware's table. An id missing from the table has CRC_EXTRA 0 there, so
//    its frames fail (bad_crc), as MISSION_REQUEST_INT and MISSION_ITEM_INT do on a 2.x board.
//  - A wrong first checksum byte ends the candidate at once, and if that byte is 0xFE a new candidate starts
//    on it; likewise for the second byte. It never rescans the bytes of a failed candidate.
//
// Frames are delivered as mavlink::Parser delivers them: payload zero-extended to the message's length.
#include <cstdint>
#include <span>
#include <vector>

#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::apmsim {

struct LegacyParserStats {
    std::uint64_t frames_ok = 0;
    std::uint64_t bad_crc = 0;        // candidates whose checksum failed (damage, or an id without CRC_EXTRA)
    std::uint64_t v2_starts = 0;      // 0xFD met while idle: MAVLink 2 frames the board could not read
    std::uint64_t garbage_bytes = 0;  // bytes skipped while idle (the 0xFD ones included)
};

class LegacyParser {
  public:
    /// `unknown_ids`: message ids the firmware's table lacks (checked with CRC_EXTRA 0).
    explicit LegacyParser(std::vector<std::uint32_t> unknown_ids = {}) : unknown_(std::move(unknown_ids)) {}

    template <class OnFrame>
    void push(std::span<const std::uint8_t> bytes, OnFrame&& on_frame) {
        for (std::uint8_t c : bytes) {
            if (step(c)) {
                on_frame(static_cast<const mavlink::Frame&>(frame_));
            }
        }
    }
    const LegacyParserStats& stats() const { return stats_; }

  private:
    enum class State : std::uint8_t { Idle, Length, Seq, Sysid, Compid, Msgid, Payload, Crc1, Crc2 };
    /// True when frame_ holds a frame that just passed its checksum.
    bool step(std::uint8_t c);
    void start();
    std::uint8_t crc_extra(std::uint8_t msgid) const;

    std::vector<std::uint32_t> unknown_;
    State state_ = State::Idle;
    std::uint16_t crc_ = 0;
    std::uint8_t length_ = 0;
    std::size_t index_ = 0;
    mavlink::Frame frame_{};
    LegacyParserStats stats_{};
};

}  // namespace airseg::apmsim
