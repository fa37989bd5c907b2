#pragma once
// MAVLink FTP (the payload of FILE_TRANSFER_PROTOCOL), as https://mavlink.io/en/services/ftp.html defines it:
// a 12-byte header (seq_number u16, session u8, opcode u8, size u8, req_opcode u8, burst_complete u8,
// padding u8, offset u32, little-endian) and up to 239 data bytes. The gate reads it to keep mission writes
// out; the simulated board serves it.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace airseg::autopilot::mavftp {

enum class Opcode : std::uint8_t {
    None = 0,
    TerminateSession = 1,
    ResetSessions = 2,
    ListDirectory = 3,
    OpenFileRO = 4,
    ReadFile = 5,
    CreateFile = 6,
    WriteFile = 7,
    RemoveFile = 8,
    CreateDirectory = 9,
    RemoveDirectory = 10,
    OpenFileWO = 11,
    TruncateFile = 12,
    Rename = 13,
    CalcFileCRC32 = 14,
    BurstReadFile = 15,
    Ack = 128,
    Nak = 129,
};

/// The first data byte of a NAK.
enum class Error : std::uint8_t {
    None = 0,
    Fail = 1,
    FailErrno = 2,  // data[1] holds the errno
    InvalidDataSize = 3,
    InvalidSession = 4,
    NoSessionsAvailable = 5,
    Eof = 6,
    UnknownCommand = 7,
    FileExists = 8,
    FileProtected = 9,
    FileNotFound = 10,
};

inline constexpr std::size_t kHeaderSize = 12;
inline constexpr std::size_t kMaxData = 239;  // 251 payload bytes less the header
inline constexpr std::size_t kPayloadSize = kHeaderSize + kMaxData;

struct Packet {
    std::uint16_t seq = 0;
    std::uint8_t session = 0;
    Opcode opcode = Opcode::None;
    std::uint8_t size = 0;  // data bytes that count (at most kMaxData)
    Opcode req_opcode = Opcode::None;
    std::uint8_t burst_complete = 0;
    std::uint32_t offset = 0;
    std::array<std::uint8_t, kMaxData> data{};

    /// The data bytes that count: `size` of them, cut at kMaxData whatever a peer claims.
    [[nodiscard]] std::span<const std::uint8_t> bytes() const {
        return std::span(data).first(std::min<std::size_t>(size, kMaxData));
    }
    /// The data as a path: up to the first NUL or `size` bytes.
    [[nodiscard]] std::string_view path(std::size_t from = 0) const {
        const auto b = bytes();
        if (from >= b.size()) {
            return {};
        }
        const auto* start = reinterpret_cast<const char*>(b.data()) + from;
        const auto* end = std::find(start, reinterpret_cast<const char*>(b.data()) + b.size(), '\0');
        return {start, static_cast<std::size_t>(end - start)};
    }
};

/// The packet in a FILE_TRANSFER_PROTOCOL payload (251 bytes; a shorter span reads as zero-padded).
inline Packet decode(std::span<const std::uint8_t> payload) {
    std::array<std::uint8_t, kPayloadSize> p{};
    std::copy_n(payload.begin(), std::min(payload.size(), p.size()), p.begin());
    Packet pk;
    pk.seq = static_cast<std::uint16_t>(p[0] | p[1] << 8);
    pk.session = p[2];
    pk.opcode = static_cast<Opcode>(p[3]);
    pk.size = p[4];
    pk.req_opcode = static_cast<Opcode>(p[5]);
    pk.burst_complete = p[6];
    pk.offset = std::uint32_t{p[8]} | std::uint32_t{p[9]} << 8 | std::uint32_t{p[10]} << 16 |
                std::uint32_t{p[11]} << 24;
    std::copy(p.begin() + kHeaderSize, p.end(), pk.data.begin());
    return pk;
}

inline std::array<std::uint8_t, kPayloadSize> encode(const Packet& pk) {
    std::array<std::uint8_t, kPayloadSize> p{};
    p[0] = static_cast<std::uint8_t>(pk.seq);
    p[1] = static_cast<std::uint8_t>(pk.seq >> 8);
    p[2] = pk.session;
    p[3] = static_cast<std::uint8_t>(pk.opcode);
    p[4] = pk.size;
    p[5] = static_cast<std::uint8_t>(pk.req_opcode);
    p[6] = pk.burst_complete;
    for (int i = 0; i < 4; ++i) {
        p[8 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(pk.offset >> (8 * i));
    }
    std::copy(pk.data.begin(), pk.data.end(), p.begin() + kHeaderSize);
    return p;
}

/// A request of `op` naming `path` (cut at kMaxData bytes) from `offset`; without a path, `size` is its data
/// size (a read's block size).
inline Packet request(Opcode op, std::string_view path = {}, std::uint32_t offset = 0, std::uint8_t size = 0) {
    Packet p;
    p.opcode = op;
    p.offset = offset;
    const std::size_t n = std::min(path.size(), kMaxData);
    std::copy_n(path.begin(), n, p.data.begin());
    p.size = n > 0 ? static_cast<std::uint8_t>(n) : size;
    return p;
}

/// The answer to `request` that a server sends: seq one on, the request's opcode in req_opcode.
inline Packet reply_to(const Packet& request, Opcode opcode) {
    Packet r;
    r.seq = static_cast<std::uint16_t>(request.seq + 1);
    r.session = request.session;
    r.opcode = opcode;
    r.req_opcode = request.opcode;
    r.offset = request.offset;
    return r;
}

/// A NAK with `error` (size 1; FailErrno also carries `errno_value`).
inline Packet nak(const Packet& request, Error error, std::uint8_t errno_value = 0) {
    Packet r = reply_to(request, Opcode::Nak);
    r.data[0] = static_cast<std::uint8_t>(error);
    r.size = 1;
    if (error == Error::FailErrno) {
        r.data[1] = errno_value;
        r.size = 2;
    }
    return r;
}

/// Operations that create, change or remove what a path names (the path is in the data; Rename has two).
inline bool writes_path(Opcode op) {
    switch (op) {
        case Opcode::CreateFile:
        case Opcode::RemoveFile:
        case Opcode::CreateDirectory:
        case Opcode::RemoveDirectory:
        case Opcode::OpenFileWO:
        case Opcode::TruncateFile:
        case Opcode::Rename:
            return true;
        default:
            return false;
    }
}

}  // namespace airseg::autopilot::mavftp
