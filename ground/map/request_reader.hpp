#pragma once
// Reads the requests of one connection with Beast's HTTP/1.1 parser, sans-IO: the session feeds the bytes it
// reads and takes whole requests, one after another (what a client pipelines stays buffered for the next).
// Beast parses; this adds the map's limits and strictness on top and turns each request into an
// http::Request, or into a refusal with its status and reason. After a refusal the connection is unusable
// (its message boundaries are lost): the session answers it and closes.
//
//   feed(bytes) -> Incomplete (read more) | Done (take()) | Failed (status(), error())
//   take()      -> the request; then feed({}) parses what was pipelined behind it
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "ground/map/beast.hpp"
#include "ground/map/http.hpp"

namespace airseg::ground::http {

struct Limits {
    std::size_t head_bytes = 16 * 1024;  // request line and headers
    std::size_t headers = 64;
    std::size_t target_bytes = 2048;
    std::size_t body_bytes = 1024 * 1024;
};

class RequestReader {
  public:
    enum class State { Incomplete, Done, Failed };

    explicit RequestReader(Limits limits = {});
    /// Takes the next bytes read (may be empty: parses what is buffered).
    State feed(std::string_view bytes);
    State state() const { return state_; }
    /// When Done: the request; the reader goes on with the next one.
    Request take();
    /// Whether any byte of the next request has arrived (a request begun, or pipelined).
    bool started() const { return buffer_.size() > 0 || parser_->got_some(); }
    /// When Failed: the status to answer (400, 413, 414, 431, 501, 505) and why.
    int error_status() const { return error_status_; }
    const std::string& error() const { return error_; }

  private:
    // A dynamic body grows with what arrives (a string body would reserve the whole Content-Length at once).
    using Parser = beast_http::request_parser<beast_http::dynamic_body>;

    State fail(int status, std::string why);
    State fail(const beast::error_code& ec);
    /// The map's own checks of a whole head; fails or leaves the state as it is.
    State check_head();
    void new_parser();

    Limits limits_;
    State state_ = State::Incomplete;
    beast::flat_buffer buffer_;
    std::optional<Parser> parser_;
    bool head_checked_ = false;
    std::optional<Request> request_;
    int error_status_ = 0;
    std::string error_;
};

}  // namespace airseg::ground::http
