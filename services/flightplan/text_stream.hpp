#pragma once
// An istream over text the caller keeps alive, read where it lies: YAML::Load would copy it into a string,
// then into a stringstream, which for a long plan is twice its size more at the peak.
#include <istream>
#include <streambuf>
#include <string_view>

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

}  // namespace airseg::flightplan
