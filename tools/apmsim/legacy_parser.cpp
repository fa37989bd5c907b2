#include "tools/apmsim/legacy_parser.hpp"

#include <algorithm>

#include "services/autopilot/mavlink/crc.hpp"
#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

// The X.25 checksum one byte at a time, as crc_accumulate() of the MAVLink C library does it.
std::uint16_t crc_add(std::uint16_t crc, std::uint8_t byte) {
    std::uint8_t tmp = byte ^ static_cast<std::uint8_t>(crc & 0xFF);
    tmp = static_cast<std::uint8_t>(tmp ^ (tmp << 4));
    return static_cast<std::uint16_t>((crc >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
}

}  // namespace

void LegacyParser::start() {
    state_ = State::Length;
    crc_ = mv::Crc16::kInitial;
}

std::uint8_t LegacyParser::crc_extra(std::uint8_t msgid) const {
    if (std::find(unknown_.begin(), unknown_.end(), msgid) != unknown_.end()) {
        return 0;
    }
    const mv::MessageInfo* info = mv::find_message(msgid);
    return info != nullptr ? info->crc_extra : 0;  // the generated table has 0 for ids it does not define
}

bool LegacyParser::step(std::uint8_t c) {
    switch (state_) {
        case State::Idle:
            if (c == mv::kMagicV1) {
                start();
            } else {
                ++stats_.garbage_bytes;
                if (c == mv::kMagicV2) {
                    ++stats_.v2_starts;
                }
            }
            return false;
        case State::Length:
            length_ = c;
            index_ = 0;
            crc_ = crc_add(crc_, c);
            state_ = State::Seq;
            return false;
        case State::Seq:
            frame_.seq = c;
            crc_ = crc_add(crc_, c);
            state_ = State::Sysid;
            return false;
        case State::Sysid:
            frame_.sysid = c;
            crc_ = crc_add(crc_, c);
            state_ = State::Compid;
            return false;
        case State::Compid:
            frame_.compid = c;
            crc_ = crc_add(crc_, c);
            state_ = State::Msgid;
            return false;
        case State::Msgid:
            frame_.msgid = c;
            crc_ = crc_add(crc_, c);
            frame_.payload.fill(0);
            state_ = length_ == 0 ? State::Crc1 : State::Payload;
            return false;
        case State::Payload:
            frame_.payload[index_++] = c;
            crc_ = crc_add(crc_, c);
            if (index_ == length_) {
                state_ = State::Crc1;
            }
            return false;
        case State::Crc1:
            crc_ = crc_add(crc_, crc_extra(static_cast<std::uint8_t>(frame_.msgid)));
            if (c != (crc_ & 0xFF)) {
                ++stats_.bad_crc;
                state_ = State::Idle;
                if (c == mv::kMagicV1) {
                    start();
                }
                return false;
            }
            state_ = State::Crc2;
            return false;
        case State::Crc2:
            state_ = State::Idle;
            if (c != (crc_ >> 8)) {
                ++stats_.bad_crc;
                if (c == mv::kMagicV1) {
                    start();
                }
                return false;
            }
            break;
    }
    ++stats_.frames_ok;
    const mv::MessageInfo* info = mv::find_message(frame_.msgid);
    frame_.version = mv::Version::V1;
    frame_.incompat_flags = 0;
    frame_.compat_flags = 0;
    frame_.is_signed = false;
    frame_.checksum_verified = true;
    frame_.wire_length = length_;
    frame_.payload_length =
        static_cast<std::uint8_t>(std::max<std::size_t>(length_, info != nullptr ? info->length : 0));
    return true;
}

}  // namespace airseg::apmsim
