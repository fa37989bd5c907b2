#pragma once
// An istream over text the caller keeps alive, read where it lies: YAML::Load would copy it into a string,
// then into a stringstream, which for a long plan is twice its size more at the peak.
#include <array>
#include <istream>
#include <streambuf>
#include <string_view>

#include "base/file_text.hpp"

namespace airseg::flightplan {

class TextBuffer : public std::streambuf {
  public:
    explicit TextBuffer(std::string_view text) {
        char* p = const_cast<char*>(text.data());  // get area only: never written
        setg(p, p, p + text.size());
    }
};

class TextStream : public std::istream {
  public:
    explicit TextStream(std::string_view text) : std::istream(nullptr), buffer_(text) { rdbuf(&buffer_); }

  private:
    TextBuffer buffer_;
};

/// An istream over a checked regular file (base/file_text.hpp), from its start, in steps of a few KiB at an
/// offset of its own (several may read one file). It ends at the file's cap and sets `grew` if there is more.
class FileBuffer : public std::streambuf {
  public:
    FileBuffer(const RegularFile& file, bool& grew) : file_(file), grew_(grew) {}

  protected:
    int_type underflow() override {
        if (gptr() < egptr()) {
            return traits_type::to_int_type(*gptr());
        }
        const ssize_t n = file_.read_at(buffer_.data(), buffer_.size(), offset_);
        if (n <= 0) {
            return traits_type::eof();  // a read error reads as the end: the document is then incomplete
        }
        offset_ += static_cast<std::uint64_t>(n);
        if (offset_ > file_.max_bytes()) {
            grew_ = true;
            return traits_type::eof();
        }
        setg(buffer_.data(), buffer_.data(), buffer_.data() + n);
        return traits_type::to_int_type(*gptr());
    }

  private:
    const RegularFile& file_;
    bool& grew_;
    std::uint64_t offset_ = 0;
    std::array<char, 8192> buffer_{};
};

class FileStream : public std::istream {
  public:
    FileStream(const RegularFile& file, bool& grew) : std::istream(nullptr), buffer_(file, grew) {
        rdbuf(&buffer_);
    }

  private:
    FileBuffer buffer_;
};

}  // namespace airseg::flightplan
