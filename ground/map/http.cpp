#include "ground/map/http.hpp"

#include <array>

#include "ground/map/beast.hpp"

namespace airseg::ground::http {

namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

}  // namespace

std::optional<std::string_view> Request::header(std::string_view name) const {
    for (const auto& [n, v] : headers) {
        if (n == name) {
            return std::string_view(v);
        }
    }
    return std::nullopt;
}

std::optional<std::string> percent_decode(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s[i] != '%') {
            out.push_back(s[i]);
            continue;
        }
        if (i + 2 >= s.size()) {
            return std::nullopt;
        }
        const int hi = hex_value(s[i + 1]);
        const int lo = hex_value(s[i + 2]);
        if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) {
            return std::nullopt;
        }
        out.push_back(static_cast<char>(hi * 16 + lo));
        i += 2;
    }
    return out;
}

const char* reason(int status) {
    switch (status) {
        case 200:
            return "OK";
        case 204:
            return "No Content";
        case 400:
            return "Bad Request";
        case 403:
            return "Forbidden";
        case 404:
            return "Not Found";
        case 405:
            return "Method Not Allowed";
        case 408:
            return "Request Timeout";
        case 413:
            return "Content Too Large";
        case 414:
            return "URI Too Long";
        case 431:
            return "Request Header Fields Too Large";
        case 500:
            return "Internal Server Error";
        case 501:
            return "Not Implemented";
        case 502:
            return "Bad Gateway";
        case 503:
            return "Service Unavailable";
        case 505:
            return "HTTP Version Not Supported";
        default:
            return "Unknown";
    }
}

namespace {

/// Beast's serializer, its buffers gathered into one string.
template <typename Body>
std::string serialize(beast_http::message<false, Body>& message) {
    beast_http::serializer<false, Body> serializer(message);
    std::string out;
    beast::error_code ec;
    while (!ec && !serializer.is_done()) {
        serializer.next(ec, [&](beast::error_code&, const auto& buffers) {
            for (const auto buffer : beast::buffers_range_ref(buffers)) {
                out.append(static_cast<const char*>(buffer.data()), buffer.size());
            }
            serializer.consume(beast::buffer_bytes(buffers));
        });
    }
    return out;
}

template <typename Body>
void common_fields(beast_http::message<false, Body>& message, int status, Framing framing) {
    message.version(framing.version == 10 ? 10 : 11);
    message.result(static_cast<unsigned>(status));
    message.reason(reason(status));
    message.set(beast_http::field::cache_control, "no-cache");
    message.set("X-Content-Type-Options", "nosniff");
}

}  // namespace

std::string render(const Reply& reply, Framing framing) {
    beast_http::response<beast_http::string_body> message;
    common_fields(message, reply.status, framing);
    message.set(beast_http::field::content_type, reply.content_type);
    for (const auto& [name, value] : reply.headers) {
        message.set(name, value);
    }
    message.keep_alive(framing.keep_alive);
    message.content_length(reply.body.size());
    if (!framing.head) {
        message.body() = reply.body;
    }
    return serialize(message);
}

std::string render_stream_head(Framing framing) {
    beast_http::response<beast_http::empty_body> message;
    common_fields(message, 200, framing);
    message.set(beast_http::field::content_type, "text/event-stream");
    message.keep_alive(false);
    return serialize(message);
}

Reply error_reply(int status, const std::string& why,
                  std::vector<std::pair<std::string, std::string>> headers) {
    return Reply{status, "text/plain; charset=utf-8",
                 std::to_string(status) + " " + reason(status) + ": " + why + "\n", std::move(headers)};
}

std::string_view content_type_for(std::string_view file_name) {
    static constexpr std::array<std::pair<std::string_view, std::string_view>, 9> kTypes{{
        {".html", "text/html; charset=utf-8"},
        {".js", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},
        {".png", "image/png"},
        {".svg", "image/svg+xml"},
        {".json", "application/json"},
        {".map", "application/json"},
        {".ico", "image/x-icon"},
        {".txt", "text/plain; charset=utf-8"},
    }};
    for (const auto& [ext, type] : kTypes) {
        if (file_name.ends_with(ext)) {
            return type;
        }
    }
    return "application/octet-stream";
}

}  // namespace airseg::ground::http
