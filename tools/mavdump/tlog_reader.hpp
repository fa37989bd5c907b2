#pragma once
// Splits a telemetry log (.tlog: records of an 8-byte big-endian microsecond timestamp followed by one
// MAVLink frame) into its records. Sans-IO: bytes in, (timestamp, frame bytes) out. A record whose frame
// does not start right after its timestamp is resynchronised byte by byte (skipped_bytes counts them).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::mavdump {

class TlogReader {
  public:
    static constexpr std::size_t kTimestampLength = 8;

    /// Calls on_record(std::uint64_t timestamp_us, std::span<const std::uint8_t> frame) per complete record.
    template <class OnRecord>
    void push(std::span<const std::uint8_t> bytes, OnRecord&& on_record) {
        buf_.insert(buf_.end(), bytes.begin(), bytes.end());
        std::size_t pos = 0;
        while (true) {
            const std::size_t need = record_length(pos);
            if (need == 0 || buf_.size() - pos < need) {
                break;
            }
            if (need == 1) {  // no frame start after this "timestamp": slide by one byte
                ++skipped_;
                ++pos;
                continue;
            }
            std::uint64_t t = 0;
            for (std::size_t i = 0; i < kTimestampLength; ++i) {
                t = (t << 8) | buf_[pos + i];
            }
            on_record(t, std::span<const std::uint8_t>(buf_.data() + pos + kTimestampLength,
                                                       need - kTimestampLength));
            pos += need;
        }
        buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(pos));
    }

    /// Bytes left over at the end of the log (an incomplete last record) join skipped_bytes.
    void finish() {
        skipped_ += buf_.size();
        buf_.clear();
    }
    std::uint64_t skipped_bytes() const { return skipped_; }

  private:
    // 0: more bytes needed to tell; 1: not a record start; otherwise the record's full length.
    std::size_t record_length(std::size_t pos) const {
        const std::size_t avail = buf_.size() - pos;
        if (avail <= kTimestampLength) {
            return 0;
        }
        const std::uint8_t* p = buf_.data() + pos + kTimestampLength;
        if (p[0] != mavlink::kMagicV1 && p[0] != mavlink::kMagicV2) {
            return 1;
        }
        const bool v1 = p[0] == mavlink::kMagicV1;
        const std::size_t header = v1 ? mavlink::kHeaderLengthV1 : mavlink::kHeaderLengthV2;
        if (avail < kTimestampLength + header) {
            return 0;
        }
        const bool is_signed = !v1 && (p[2] & mavlink::kIncompatSigned) != 0;
        return kTimestampLength + header + p[1] + mavlink::kChecksumLength +
               (is_signed ? mavlink::kSignatureLength : 0);
    }

    std::vector<std::uint8_t> buf_;
    std::uint64_t skipped_ = 0;
};

}  // namespace airseg::mavdump
