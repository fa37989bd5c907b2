#include "services/autopilot/tlog_writer.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace airseg::autopilot {

std::vector<std::string> TlogConfig::validate(const TlogConfig& c) {
    std::vector<std::string> out;
    if (c.enabled && c.path.empty()) {
        out.push_back("autopilot.tlog.path: needed when autopilot.tlog.enabled is true");
    }
    if (c.max_bytes < 64 * 1024) {
        out.push_back("autopilot.tlog.max_bytes: " + std::to_string(c.max_bytes) + " is below 65536");
    }
    if (c.keep > 100) {
        out.push_back("autopilot.tlog.keep: " + std::to_string(c.keep) + " is above 100");
    }
    return out;
}

TlogWriter::TlogWriter(TlogConfig config) : config_(std::move(config)) {
    if (config_.enabled) {
        buffer_.reserve(kFlushAt + 512);
    }
}

TlogWriter::~TlogWriter() {
    flush();
    close();
}

void TlogWriter::fail(const char* what, int err) {
    ++stats_.write_errors;
    stats_.last_error = std::string(what) + " " + config_.path + ": " + std::strerror(err);
}

bool TlogWriter::open(TimePoint now) {
    if (fd_ >= 0) {
        return true;
    }
    if (now < next_open_attempt_) {
        return false;
    }
    next_open_attempt_ = now + config_.reopen_interval;
    fd_ = ::open(config_.path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0) {
        fail("open", errno);
        return false;
    }
    struct stat st {};
    file_bytes_ = ::fstat(fd_, &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
    return true;
}

void TlogWriter::close() {
    if (fd_ >= 0) {
        ::close(fd_);
        fd_ = -1;
    }
}

void TlogWriter::rotate(TimePoint now) {
    flush();
    close();
    const auto name = [&](unsigned i) {
        return i == 0 ? config_.path : config_.path + "." + std::to_string(i);
    };
    if (config_.keep == 0) {
        std::remove(config_.path.c_str());
    } else {
        std::remove(name(config_.keep).c_str());
        for (unsigned i = config_.keep; i > 0; --i) {
            std::rename(name(i - 1).c_str(), name(i).c_str());  // missing files are fine
        }
    }
    ++stats_.rotations;
    file_bytes_ = 0;
    next_open_attempt_ = TimePoint::min();
    open(now);
}

void TlogWriter::record(std::span<const std::uint8_t> frame, WallTime at, TimePoint now) {
    if (!config_.enabled) {
        return;
    }
    const std::size_t record_size = 8 + frame.size();
    if (fd_ < 0 && !open(now)) {
        ++stats_.dropped_frames;
        return;
    }
    if (file_bytes_ + record_size > config_.max_bytes && file_bytes_ > 0) {
        rotate(now);
        if (fd_ < 0) {
            ++stats_.dropped_frames;
            return;
        }
    }
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(at.time_since_epoch()).count();
    const auto u = static_cast<std::uint64_t>(us);
    if (buffer_.empty()) {
        flush_due_ = now + config_.flush_interval;
    }
    for (int shift = 56; shift >= 0; shift -= 8) {
        buffer_.push_back(static_cast<std::uint8_t>(u >> shift));
    }
    buffer_.insert(buffer_.end(), frame.begin(), frame.end());
    ++buffered_frames_;
    file_bytes_ += record_size;
    if (buffer_.size() >= kFlushAt) {
        flush();
    }
}

void TlogWriter::handle_timeout(TimePoint now) {
    if (now >= flush_due_) {
        flush();
    }
}

void TlogWriter::flush() {
    flush_due_ = kNever;
    if (buffer_.empty()) {
        return;
    }
    const off_t start = fd_ >= 0 ? ::lseek(fd_, 0, SEEK_END) : -1;
    std::size_t done = 0;
    while (fd_ >= 0 && done < buffer_.size()) {
        const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            fail("write", errno);
            // Cut a partly written record off again so that readers never lose step; then try later.
            if (start >= 0 && ::ftruncate(fd_, start) == 0) {
                done = 0;
            }
            close();
            break;
        }
        done += static_cast<std::size_t>(n);
    }
    if (done == buffer_.size()) {
        stats_.frames += buffered_frames_;
    } else {
        stats_.dropped_frames += buffered_frames_;
        file_bytes_ -= std::min<std::uint64_t>(file_bytes_, buffer_.size() - done);
    }
    stats_.bytes += done;
    buffer_.clear();
    buffered_frames_ = 0;
}

}  // namespace airseg::autopilot
