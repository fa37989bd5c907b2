#pragma once
// The little HTTP/1.1 the map page needs, sans-IO: one request parsed from bytes as they arrive (strictly:
// CRLF line ends, a Host header, a Content-Length body only, bounded sizes), and responses rendered to bytes.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace airseg::ground::http {

struct Request {
    std::string method;
    std::string path;   // the target without its query, percent-decoded
    std::string query;  // after '?', as sent
    std::vector<std::pair<std::string, std::string>> headers;  // names lower-cased
    std::string body;
    /// The first header with this (lower-case) name.
    std::optional<std::string_view> header(std::string_view name) const;
};

struct Limits {
    std::size_t head_bytes = 16 * 1024;  // request line and headers
    std::size_t headers = 64;
    std::size_t body_bytes = 1024 * 1024;
};

class RequestParser {
  public:
    enum class State { Incomplete, Done, Failed };

    explicit RequestParser(Limits limits = {}) : limits_(limits) {}
    /// Takes the next bytes; returns Done once a whole request is there (later bytes are ignored).
    State feed(std::string_view bytes);
    State state() const { return state_; }
    const Request& request() const { return request_; }
    /// When Failed: the status to answer (400, 413, 414, 431, 501, 505) and why.
    int error_status() const { return error_status_; }
    const std::string& error() const { return error_; }

  private:
    State fail(int status, std::string why);
    State parse_head(std::string_view head);

    Limits limits_;
    State state_ = State::Incomplete;
    std::string buffer_;
    bool head_done_ = false;
    std::size_t body_length_ = 0;
    Request request_;
    int error_status_ = 0;
    std::string error_;
};

/// "%2F" and friends decoded; nothing when an escape is malformed or decodes to a NUL.
std::optional<std::string> percent_decode(std::string_view s);

/// The reason phrase of a status code.
const char* reason(int status);

/// A whole response with Content-Length and "Connection: close"; `extra` headers are "Name: value" lines.
std::string response(int status, std::string_view content_type, std::string_view body,
                     const std::vector<std::string>& extra = {}, bool head_only = false);

/// The content type for a file name's extension (application/octet-stream when unknown).
std::string_view content_type_for(std::string_view file_name);

}  // namespace airseg::ground::http
