#pragma once
// The bounded queue of writes waiting for a device, shared by SerialPort and Pty: a write is admitted whole
// or not at all, and its bytes count against the bound from push() until their device write completes.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "hal/error.hpp"

namespace airseg::hal {

class WriteQueue {
  public:
    /// Queued, or QueueFull when the bytes would take the queue over max_bytes. An empty write is Queued and
    /// dropped. The caller checks that the device can take writes at all (NotOpen, NoPeer).
    WriteResult push(std::vector<std::uint8_t> bytes, std::size_t max_bytes) {
        if (bytes.empty()) {
            return WriteResult::Queued;
        }
        if (bytes.size() > max_bytes - std::min(bytes_, max_bytes)) {
            return WriteResult::QueueFull;
        }
        bytes_ += bytes.size();
        waiting_.push_back(std::move(bytes));
        return WriteResult::Queued;
    }

    bool has_waiting() const { return !waiting_.empty(); }
    /// The oldest waiting write, for a device written one write at a time.
    std::vector<std::uint8_t> take_one() {
        auto bytes = std::move(waiting_.front());
        waiting_.pop_front();
        return bytes;
    }
    /// Every waiting write, for one gathered device write.
    std::deque<std::vector<std::uint8_t>> take_all() { return std::exchange(waiting_, {}); }
    /// A device write of `size` taken bytes ended (done or failed): they no longer count.
    void written(std::size_t size) { bytes_ -= std::min(size, bytes_); }
    void clear() {
        waiting_.clear();
        bytes_ = 0;
    }
    /// Bytes waiting or being written.
    std::size_t bytes() const { return bytes_; }

  private:
    std::deque<std::vector<std::uint8_t>> waiting_;
    std::size_t bytes_ = 0;
};

}  // namespace airseg::hal
