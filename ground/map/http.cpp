#include "ground/map/http.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>

namespace airseg::ground::http {

namespace {

bool is_token_char(char c) {
    static constexpr std::string_view kSpecials = "!#$%&'*+-.^_`|~";
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
           kSpecials.find(c) != std::string_view::npos;
}

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
    return out;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) {
        s.remove_prefix(1);
    }
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) {
        s.remove_suffix(1);
    }
    return s;
}

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

RequestParser::State RequestParser::fail(int status, std::string why) {
    state_ = State::Failed;
    error_status_ = status;
    error_ = std::move(why);
    return state_;
}

RequestParser::State RequestParser::feed(std::string_view bytes) {
    if (state_ != State::Incomplete) {
        return state_;
    }
    buffer_.append(bytes);
    if (!head_done_) {
        const auto end = buffer_.find("\r\n\r\n");
        if (end == std::string::npos) {
            if (buffer_.size() > limits_.head_bytes) {
                return fail(431, "request head larger than " + std::to_string(limits_.head_bytes) + " bytes");
            }
            return state_;
        }
        if (end + 4 > limits_.head_bytes) {
            return fail(431, "request head larger than " + std::to_string(limits_.head_bytes) + " bytes");
        }
        if (parse_head(std::string_view(buffer_).substr(0, end + 2)) == State::Failed) {
            return state_;
        }
        head_done_ = true;
        buffer_.erase(0, end + 4);
    }
    if (buffer_.size() >= body_length_) {
        request_.body = buffer_.substr(0, body_length_);
        buffer_.clear();
        state_ = State::Done;
    }
    return state_;
}

RequestParser::State RequestParser::parse_head(std::string_view head) {
    // Request line: METHOD SP target SP HTTP/1.x
    const auto line_end = head.find("\r\n");
    const std::string_view line = head.substr(0, line_end);
    const auto sp1 = line.find(' ');
    const auto sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
    if (sp1 == std::string_view::npos || sp2 == std::string_view::npos ||
        line.find(' ', sp2 + 1) != std::string_view::npos) {
        return fail(400, "the request line is not \"METHOD /path HTTP/1.1\"");
    }
    const auto method = line.substr(0, sp1);
    const auto target = line.substr(sp1 + 1, sp2 - sp1 - 1);
    const auto version = line.substr(sp2 + 1);
    if (method.empty() || !std::all_of(method.begin(), method.end(), is_token_char)) {
        return fail(400, "bad method");
    }
    if (version != "HTTP/1.1" && version != "HTTP/1.0") {
        return fail(version.starts_with("HTTP/") ? 505 : 400, "only HTTP/1.0 and HTTP/1.1 are spoken here");
    }
    if (target.empty() || target.front() != '/') {
        return fail(400, "the target must be a path starting with /");
    }
    if (target.size() > 2048) {
        return fail(414, "target longer than 2048 bytes");
    }
    for (char c : target) {
        if (static_cast<unsigned char>(c) <= 0x20 || static_cast<unsigned char>(c) >= 0x7f) {
            return fail(400, "control or non-ASCII character in the target");
        }
    }
    const auto q = target.find('?');
    auto path = percent_decode(target.substr(0, q));
    if (!path) {
        return fail(400, "bad percent escape in the path");
    }
    request_.method = std::string(method);
    request_.path = std::move(*path);
    request_.query = q == std::string_view::npos ? std::string() : std::string(target.substr(q + 1));

    std::string_view rest =
        line_end == std::string_view::npos ? std::string_view() : head.substr(line_end + 2);
    while (!rest.empty()) {
        const auto eol = rest.find("\r\n");
        const std::string_view h = rest.substr(0, eol);
        rest = eol == std::string_view::npos ? std::string_view() : rest.substr(eol + 2);
        if (h.find('\n') != std::string_view::npos || h.find('\r') != std::string_view::npos) {
            return fail(400, "bare CR or LF in a header");
        }
        if (h.front() == ' ' || h.front() == '\t') {
            return fail(400, "folded header lines are not accepted");
        }
        const auto colon = h.find(':');
        if (colon == std::string_view::npos || colon == 0 ||
            !std::all_of(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(colon), is_token_char)) {
            return fail(400, "malformed header line");
        }
        if (request_.headers.size() >= limits_.headers) {
            return fail(431, "more than " + std::to_string(limits_.headers) + " headers");
        }
        request_.headers.emplace_back(lower(h.substr(0, colon)), std::string(trim(h.substr(colon + 1))));
    }
    if (version == "HTTP/1.1" && !request_.header("host")) {
        return fail(400, "an HTTP/1.1 request needs a Host header");
    }
    if (request_.header("transfer-encoding")) {
        return fail(501, "only bodies with a Content-Length are accepted, not Transfer-Encoding");
    }
    int lengths = 0;
    for (const auto& [n, v] : request_.headers) {
        if (n != "content-length") {
            continue;
        }
        if (++lengths > 1) {
            return fail(400, "more than one Content-Length");
        }
        // 64 bits whatever size_t is: a length beyond a 32-bit board's size_t is too large, not malformed.
        std::uint64_t value = 0;
        const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
        const bool digits_only = !v.empty() && ptr == v.data() + v.size();
        if (!digits_only || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
            return fail(400, "Content-Length is not a number");
        }
        if (ec == std::errc::result_out_of_range || value > limits_.body_bytes) {
            return fail(413, "body larger than " + std::to_string(limits_.body_bytes) + " bytes");
        }
        body_length_ = static_cast<std::size_t>(value);  // at most body_bytes
    }
    return state_;
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

std::string response(int status, std::string_view content_type, std::string_view body,
                     const std::vector<std::string>& extra, bool head_only) {
    std::string out = "HTTP/1.1 " + std::to_string(status) + " " + reason(status) + "\r\n";
    out += "Content-Type: ";
    out += content_type;
    out += "\r\nContent-Length: " + std::to_string(body.size()) + "\r\n";
    out += "Cache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n";
    for (const auto& h : extra) {
        out += h + "\r\n";
    }
    out += "\r\n";
    if (!head_only) {
        out += body;
    }
    return out;
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
