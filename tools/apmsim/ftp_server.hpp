#pragma once
// The board's MAVLink FTP server, sans-IO, as ArduPilot's AP_MAVLink FTP serves its @PARAM file system: one
// session at a time; OpenFileRO, ReadFile, BurstReadFile, TerminateSession, ResetSessions and ListDirectory;
// one file, @PARAM/param.pck (param_pack.hpp; "?start=N&count=M" picks a range), listed in @PARAM and
// its directory in the root. Everything else is answered with the NAK ArduPilot gives: FileNotFound for
// another path, NoSessionsAvailable while a session is open, InvalidSession for another session, EOF past
// the end, Fail for a read of param.pck whose size differs from the first read's, UnknownCommand for
// operations it does not serve (writes among them: the simulated board has no writable files).
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "services/autopilot/mavftp.hpp"
#include "tools/apmsim/param_table.hpp"

namespace airseg::apmsim {

namespace ftp = airseg::autopilot::mavftp;

struct FtpServerStats {
    std::uint64_t requests = 0;
    std::uint64_t naks = 0;
    std::uint64_t bytes_read = 0;  // file bytes sent in ReadFile and BurstReadFile answers
};

class FtpServer {
  public:
    /// Replies one burst may carry before burst_complete (ArduPilot paces a burst; this bounds one).
    static constexpr std::size_t kMaxBurst = 64;
    static constexpr std::uint8_t kSession = 0;

    explicit FtpServer(const ParamTable& params) : params_(params) {}

    /// The answers to one request, in order (one, or a burst's several).
    std::vector<ftp::Packet> handle(const ftp::Packet& request);
    /// A reboot closes the session.
    void reset() { open_.reset(); }
    [[nodiscard]] const FtpServerStats& stats() const { return stats_; }

  private:
    struct OpenFile {
        std::size_t start = 0;
        std::size_t count = 0;
        std::size_t block = 0;  // read size fixed by the first read (0: none yet)
        std::vector<std::uint8_t> content;
    };
    ftp::Packet nak(const ftp::Packet& request, ftp::Error error);
    ftp::Packet open_ro(const ftp::Packet& request);
    ftp::Packet list(const ftp::Packet& request);
    std::vector<ftp::Packet> read(const ftp::Packet& request, bool burst);
    std::optional<ftp::Error> check_session(const ftp::Packet& request) const;

    const ParamTable& params_;
    std::optional<OpenFile> open_;
    FtpServerStats stats_;
};

}  // namespace airseg::apmsim
