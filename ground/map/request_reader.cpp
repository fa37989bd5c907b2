#include "ground/map/request_reader.hpp"

#include <algorithm>

namespace airseg::ground::http {

namespace {

// Pipelined requests and a head still arriving wait in the buffer; beyond this much the client is sending far
// ahead of the answers.
constexpr std::size_t kAheadBytes = 64 * 1024;

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
    return out;
}

constexpr std::string_view kRequestLine = "the request line is not \"METHOD /path HTTP/1.1\"";

}  // namespace

RequestReader::RequestReader(Limits limits) : limits_(limits), buffer_(limits.head_bytes + kAheadBytes) {
    new_parser();
}

void RequestReader::new_parser() {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(limits_.head_bytes));
    parser_->body_limit(limits_.body_bytes);
    head_checked_ = false;
    request_.reset();
}

RequestReader::State RequestReader::fail(int status, std::string why) {
    state_ = State::Failed;
    error_status_ = status;
    error_ = std::move(why);
    return state_;
}

RequestReader::State RequestReader::fail(const beast::error_code& ec) {
    using Error = beast_http::error;
    const std::string beast_says = " (" + ec.message() + ")";
    if (ec == Error::header_limit || ec == Error::buffer_overflow) {
        return fail(431, "request head larger than " + std::to_string(limits_.head_bytes) + " bytes");
    }
    if (ec == Error::body_limit) {
        return fail(413, "body larger than " + std::to_string(limits_.body_bytes) + " bytes");
    }
    if (ec == Error::bad_version || ec == Error::bad_value || ec == Error::bad_field ||
        ec == Error::bad_line_ending) {
        // Beast stops where a line ends in a bare LF: at the version, or inside a header's name or value.
        const std::string_view seen(static_cast<const char*>(buffer_.data().data()), buffer_.size());
        for (auto lf = seen.find('\n'); lf != std::string_view::npos; lf = seen.find('\n', lf + 1)) {
            if (lf == 0 || seen[lf - 1] != '\r') {
                return fail(400, "a line ends in a bare LF: HTTP/1.1 lines end in CRLF");
            }
        }
        if (ec == Error::bad_version) {
            const auto line = seen.substr(0, seen.find_first_of("\r\n"));
            const auto space = line.rfind(' ');
            const auto version = line.substr(space == std::string_view::npos ? 0 : space + 1);
            if (version.starts_with("HTTP/") && version != "HTTP/1.0" && version != "HTTP/1.1") {
                return fail(505, "only HTTP/1.0 and HTTP/1.1 are spoken here");
            }
            return fail(400, std::string(kRequestLine) + beast_says);
        }
    }
    if (ec == Error::bad_method || ec == Error::bad_target) {
        return fail(400, std::string(kRequestLine) + beast_says);
    }
    if (ec == Error::bad_line_ending) {
        return fail(400, "a bare CR or LF: HTTP/1.1 lines end in CRLF");
    }
    if (ec == Error::bad_field || ec == Error::bad_value) {
        return fail(400, "malformed header line" + beast_says);
    }
    if (ec == Error::bad_content_length) {
        return fail(400, "Content-Length is not a number, or more than one and different, or too large");
    }
    if (ec == Error::bad_transfer_encoding) {
        return fail(501, "only bodies with a Content-Length are accepted, not Transfer-Encoding");
    }
    return fail(400, "malformed request" + beast_says);
}

RequestReader::State RequestReader::feed(std::string_view bytes) {
    if (state_ == State::Failed) {
        return state_;
    }
    if (!bytes.empty()) {
        if (bytes.size() > buffer_.max_size() - buffer_.size()) {
            return fail(431, "more than " + std::to_string(buffer_.max_size()) +
                                 " bytes sent ahead of the answers or in a request head");
        }
        buffer_.commit(asio::buffer_copy(buffer_.prepare(bytes.size()), asio::buffer(bytes)));
    }
    if (state_ == State::Done) {
        return state_;  // the request waits to be taken; what follows stays buffered
    }
    while (!parser_->is_done() && buffer_.size() > 0) {
        beast::error_code ec;
        const auto used = parser_->put(buffer_.data(), ec);
        if (ec == beast_http::error::need_more) {
            break;
        }
        if (ec) {
            return fail(ec);
        }
        buffer_.consume(used);
        if (parser_->is_header_done() && !head_checked_) {
            if (check_head() == State::Failed) {
                return state_;
            }
            head_checked_ = true;
        }
        if (used == 0) {
            break;
        }
    }
    if (parser_->is_done()) {
        auto& message = parser_->get();
        request_->body = beast::buffers_to_string(message.body().data());
        state_ = State::Done;
    }
    return state_;
}

RequestReader::State RequestReader::check_head() {
    const auto& message = parser_->get();
    if (message.version() != 10 && message.version() != 11) {
        return fail(505, "only HTTP/1.0 and HTTP/1.1 are spoken here");
    }
    const std::string_view target(message.target().data(), message.target().size());
    if (target.empty() || target.front() != '/') {
        return fail(400, "the target must be a path starting with /");
    }
    if (target.size() > limits_.target_bytes) {
        return fail(414, "target longer than " + std::to_string(limits_.target_bytes) + " bytes");
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
    Request request;
    request.method = std::string(message.method_string());
    request.path = std::move(*path);
    request.query = q == std::string_view::npos ? std::string() : std::string(target.substr(q + 1));
    request.version = message.version();
    request.keep_alive = message.keep_alive();
    for (const auto& field : message) {
        if (request.headers.size() >= limits_.headers) {
            return fail(431, "more than " + std::to_string(limits_.headers) + " headers");
        }
        request.headers.emplace_back(
            lower(std::string_view(field.name_string().data(), field.name_string().size())),
            std::string(field.value()));
    }
    if (request.version == 11 && !request.header("host")) {
        return fail(400, "an HTTP/1.1 request needs a Host header");
    }
    if (request.header("transfer-encoding")) {
        return fail(501, "only bodies with a Content-Length are accepted, not Transfer-Encoding");
    }
    request_ = std::move(request);
    return state_;
}

Request RequestReader::take() {
    if (state_ != State::Done) {
        return {};
    }
    Request out = std::move(*request_);
    state_ = State::Incomplete;
    new_parser();
    return out;
}

}  // namespace airseg::ground::http
