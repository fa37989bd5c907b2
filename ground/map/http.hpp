#pragma once
// The map's HTTP vocabulary, apart from the wire (Boost.Beast reads and writes it: request_reader.hpp,
// render()): a request as the routes and the guard see it, a reply as they give it, and the helpers both use.
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
    unsigned version = 11;    // 10 or 11
    bool keep_alive = false;  // what the client asked for (HTTP/1.1 unless "Connection: close")
    /// The first header with this (lower-case) name.
    std::optional<std::string_view> header(std::string_view name) const;
};

/// A whole answer (Content-Length framed); how it is framed on the connection is the session's.
struct Reply {
    int status = 200;
    std::string content_type;
    std::string body;
    std::vector<std::pair<std::string, std::string>> headers;  // extra ones: Allow, Content-Disposition
};

/// How a reply goes out: the request's version, whether it was HEAD, whether the connection stays open.
struct Framing {
    unsigned version = 11;
    bool head = false;
    bool keep_alive = false;
};

/// The reply as bytes (Beast's serializer): status line, Content-Type, Content-Length, no-cache, nosniff, the
/// extra headers, "Connection: close" unless kept alive, and the body unless HEAD.
std::string render(const Reply& reply, Framing framing);

/// The head of a server-sent event stream (no length: it ends when the connection does).
std::string render_stream_head(Framing framing);

/// A plain-text refusal: "404 Not Found: why".
Reply error_reply(int status, const std::string& why,
                  std::vector<std::pair<std::string, std::string>> headers = {});

/// "%2F" and friends decoded; nothing when an escape is malformed or decodes to a NUL.
std::optional<std::string> percent_decode(std::string_view s);

/// The reason phrase of a status code.
const char* reason(int status);

/// The content type for a file name's extension (application/octet-stream when unknown).
std::string_view content_type_for(std::string_view file_name);

}  // namespace airseg::ground::http
