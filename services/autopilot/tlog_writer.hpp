#pragma once
// The flight recorder: every MAVLink frame to and from the autopilot appended to a .tlog, the format
// MAVProxy, Mission Planner and airseg-mavdump --tlog read: per frame an 8-byte big-endian timestamp
// (microseconds since 1970) and the frame's bytes.
//
// Size cap and rotation: when the file would pass max_bytes it is closed and renamed PATH.1 (PATH.1 to
// PATH.2, ..., the oldest beyond `keep` removed), and a new PATH is started.
//
// Writes are batched, not one per frame (an SD card): the buffer goes to the file in one write() when it
// reaches 32 KiB, when its oldest frame has waited flush_interval (2 s), on flush() and on destruction, so a
// reader of the file during a flight is at most flush_interval behind. The writer is sans-IO about time: it
// never reads a clock. The caller passes the frame's wall-clock stamp and the steady time now, and calls
// handle_timeout(now) when poll_timeout() is due (kNever while nothing is buffered).
//
// A failing disk (ENOSPC, EIO, a vanished directory) never throws and never stops the caller: the buffered
// frames are dropped and counted (a partly written record is cut off again, so the file stays readable), the
// error kept for status, and the file is opened again at most every reopen_interval.
#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"

namespace airseg::autopilot {

struct TlogConfig {
    bool enabled = false;                   // autopilot.tlog.enabled
    std::string path;                       // autopilot.tlog.path, e.g. /var/log/airseg/autopilot.tlog
    std::uint64_t max_bytes = 64ull << 20;  // autopilot.tlog.max_bytes (>= 64 KiB)
    unsigned keep = 4;                      // autopilot.tlog.keep: rotated files kept (0..100)
    Duration reopen_interval = seconds(5);
    Duration flush_interval = seconds(2);  // the longest a recorded frame waits in the buffer

    static std::vector<std::string> validate(const TlogConfig& c);
};

struct TlogStats {
    std::uint64_t frames = 0;          // frames written to disk
    std::uint64_t bytes = 0;           // bytes written to disk, all files
    std::uint64_t dropped_frames = 0;  // frames lost to write errors or a closed file
    std::uint64_t write_errors = 0;
    std::uint64_t rotations = 0;
    std::string last_error;  // "write /var/log/airseg/autopilot.tlog: No space left on device"
};

class TlogWriter {
  public:
    using WallTime = std::chrono::system_clock::time_point;
    static constexpr std::size_t kFlushAt = 32 * 1024;

    explicit TlogWriter(TlogConfig config);
    ~TlogWriter();
    TlogWriter(const TlogWriter&) = delete;
    TlogWriter& operator=(const TlogWriter&) = delete;

    /// Appends one frame stamped `at` (wall clock, written into the file); `now` is the steady time, for the
    /// flush and reopen deadlines. Does nothing when disabled.
    void record(std::span<const std::uint8_t> frame, WallTime at, TimePoint now);
    /// When the oldest buffered frame is due on disk; kNever while nothing is buffered.
    [[nodiscard]] TimePoint poll_timeout() const { return flush_due_; }
    /// Writes the buffer when poll_timeout() has come; otherwise nothing.
    void handle_timeout(TimePoint now);
    /// Writes what is buffered (also done by the destructor).
    void flush();

    const TlogStats& stats() const { return stats_; }
    bool is_open() const { return fd_ >= 0; }

  private:
    bool open(TimePoint now);
    void close();
    void rotate(TimePoint now);
    void fail(const char* what, int err);

    TlogConfig config_;
    int fd_ = -1;
    std::uint64_t file_bytes_ = 0;  // in the current file, written and buffered
    std::vector<std::uint8_t> buffer_;
    std::uint64_t buffered_frames_ = 0;
    TimePoint flush_due_ = kNever;  // the oldest buffered frame's time + flush_interval
    TimePoint next_open_attempt_ = TimePoint::min();
    TlogStats stats_;
};

}  // namespace airseg::autopilot
