#include "tools/apmsim/ftp_server.hpp"

#include <algorithm>
#include <charconv>
#include <string>

#include "tools/apmsim/param_pack.hpp"

namespace airseg::apmsim {

namespace {

constexpr std::string_view kParamDir = "@PARAM";
constexpr std::string_view kParamFile = "param.pck";

std::string_view without_leading_slashes(std::string_view path) {
    while (!path.empty() && path.front() == '/') {
        path.remove_prefix(1);
    }
    return path;
}

std::string_view without_trailing_slashes(std::string_view path) {
    while (!path.empty() && path.back() == '/') {
        path.remove_suffix(1);
    }
    return path;
}

/// The value of `key` in a query string "a=1&b=2", or 0.
std::size_t query_value(std::string_view query, std::string_view key) {
    while (!query.empty()) {
        const auto amp = query.find('&');
        const auto item = query.substr(0, amp);
        if (item.size() > key.size() && item.substr(0, key.size()) == key && item[key.size()] == '=') {
            std::size_t v = 0;
            const auto digits = item.substr(key.size() + 1);
            std::from_chars(digits.data(), digits.data() + digits.size(), v);
            return v;
        }
        query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    }
    return 0;
}

std::size_t block_of(const ftp::Packet& request) {
    return request.size == 0 ? ftp::kMaxData : std::min<std::size_t>(request.size, ftp::kMaxData);
}

}  // namespace

std::vector<ftp::Packet> FtpServer::handle(const ftp::Packet& request) {
    ++stats_.requests;
    switch (request.opcode) {
        case ftp::Opcode::TerminateSession:
            if (const auto e = check_session(request)) {
                return {nak(request, *e)};
            }
            open_.reset();
            return {ftp::reply_to(request, ftp::Opcode::Ack)};
        case ftp::Opcode::ResetSessions:
            open_.reset();
            return {ftp::reply_to(request, ftp::Opcode::Ack)};
        case ftp::Opcode::ListDirectory:
            return {list(request)};
        case ftp::Opcode::OpenFileRO:
            return {open_ro(request)};
        case ftp::Opcode::ReadFile:
            return read(request, false);
        case ftp::Opcode::BurstReadFile:
            return read(request, true);
        default:
            return {nak(request, ftp::Error::UnknownCommand)};
    }
}

ftp::Packet FtpServer::nak(const ftp::Packet& request, ftp::Error error) {
    ++stats_.naks;
    return ftp::nak(request, error);
}

std::optional<ftp::Error> FtpServer::check_session(const ftp::Packet& request) const {
    if (!open_ || request.session != kSession) {
        return ftp::Error::InvalidSession;
    }
    return std::nullopt;
}

ftp::Packet FtpServer::open_ro(const ftp::Packet& request) {
    if (open_) {
        return nak(request, ftp::Error::NoSessionsAvailable);
    }
    const auto full = without_leading_slashes(request.path());
    const auto question = full.find('?');
    const auto path = full.substr(0, question);
    const auto query = question == std::string_view::npos ? std::string_view{} : full.substr(question + 1);
    if (path != std::string(kParamDir) + "/" + std::string(kParamFile)) {
        return nak(request, ftp::Error::FileNotFound);
    }
    OpenFile f;
    f.start = query_value(query, "start");
    f.count = query_value(query, "count");
    // The size a ground station is told: the file packed for full-size reads (the packing changes with the
    // read size, fixed by the first read).
    f.content = pack_params(params_, ftp::kMaxData, f.start, f.count);
    auto ack = ftp::reply_to(request, ftp::Opcode::Ack);
    ack.session = kSession;
    ack.offset = 0;
    const auto size = static_cast<std::uint32_t>(f.content.size());
    for (std::size_t i = 0; i < 4; ++i) {
        ack.data[i] = static_cast<std::uint8_t>(size >> (8 * i));
    }
    ack.size = 4;
    open_ = std::move(f);
    return ack;
}

ftp::Packet FtpServer::list(const ftp::Packet& request) {
    const auto dir = without_trailing_slashes(without_leading_slashes(request.path()));
    std::vector<std::string> entries;
    if (dir.empty()) {
        entries.push_back("D" + std::string(kParamDir));
    } else if (dir == kParamDir) {
        const auto size = pack_params(params_, ftp::kMaxData).size();
        entries.push_back("F" + std::string(kParamFile) + "\t" + std::to_string(size));
    } else {
        return nak(request, ftp::Error::FileNotFound);
    }
    if (request.offset >= entries.size()) {
        return nak(request, ftp::Error::Eof);
    }
    auto ack = ftp::reply_to(request, ftp::Opcode::Ack);
    std::size_t used = 0;
    for (std::size_t i = request.offset; i < entries.size(); ++i) {
        const auto& e = entries[i];
        if (used + e.size() + 1 > ftp::kMaxData) {
            break;
        }
        std::copy(e.begin(), e.end(), ack.data.begin() + static_cast<std::ptrdiff_t>(used));
        used += e.size() + 1;  // each entry ends with a NUL
    }
    ack.size = static_cast<std::uint8_t>(used);
    return ack;
}

std::vector<ftp::Packet> FtpServer::read(const ftp::Packet& request, bool burst) {
    if (const auto e = check_session(request)) {
        return {nak(request, *e)};
    }
    OpenFile& f = *open_;
    const std::size_t block = block_of(request);
    if (f.block == 0) {
        f.block = block;
        f.content = pack_params(params_, block, f.start, f.count);
    } else if (f.block != block) {
        return {nak(request, ftp::Error::Fail)};  // "Attempts to vary the read size ... a failed read"
    }
    if (request.offset >= f.content.size()) {
        return {nak(request, ftp::Error::Eof)};
    }
    std::vector<ftp::Packet> out;
    std::size_t offset = request.offset;
    auto seq = request.seq;
    while (offset < f.content.size()) {
        const std::size_t n = std::min(block, f.content.size() - offset);
        ftp::Packet ack = ftp::reply_to(request, ftp::Opcode::Ack);
        ack.seq = static_cast<std::uint16_t>(seq + 1);
        ack.offset = static_cast<std::uint32_t>(offset);
        std::copy_n(f.content.begin() + static_cast<std::ptrdiff_t>(offset), n, ack.data.begin());
        ack.size = static_cast<std::uint8_t>(n);
        stats_.bytes_read += n;
        offset += n;
        seq = ack.seq;
        out.push_back(ack);
        if (!burst) {
            break;
        }
        if (offset >= f.content.size() || out.size() >= kMaxBurst) {
            out.back().burst_complete = 1;
            break;
        }
    }
    return out;
}

}  // namespace airseg::apmsim
