#pragma once
// Sans-IO model of a pair of transparent serial radios (SiK/3DR, XBee, XTend class).
//
// Contract (time is always passed in; the model never reads a clock):
//   push(from, bytes, now)        host `from` writes bytes to its radio's serial port; returns how many the
//   host's
//                                 UART buffer accepted (a short count is a non-blocking write's EAGAIN).
//   poll_output(to, now)          bytes the radio at `to` has written to its host's serial port up to `now`.
//   poll_timeout()                the earliest time at which anything observable can change (an air packet
//   can start
//                                 or a byte becomes deliverable); kNever when idle. It does not announce when
//                                 UART space frees up: a driver with a blocked writer retries at its own
//                                 cadence.
//   serial_space(from, now)       how many bytes push() would accept now.
// Calls must use non-decreasing `now`. Poll output regularly: bytes already due wait in memory until polled.
//
// What is modelled, in the order a byte meets it:
//   1. Host UART: bytes leave the host at baud/10 bytes/s (8N1) into the radio; at most host_buffer are
//   queued.
//   2. Radio FIFO (radio_buffer bytes): a byte arriving while it is full is dropped (overflow) - a radio
//   without
//      hardware flow control whose air is slower than its serial line loses data exactly here.
//   3. Air: the radio gathers its FIFO into a packet of up to max_air_packet bytes and sends it when it holds
//   the
//      air. It sends a partial packet only once its host stops writing (SiK-like gathering). Half duplex: one
//      air channel for both directions, the sides alternate packets when both have data, and a change of
//      sender costs `turnaround` of dead air. Full duplex: one channel per direction. Airtime = (bytes +
//      overhead) / air rate.
//   4. Impairments of the sending direction: packet loss, outages (a packet overlapping one is lost), a radio
//   that
//      is down, then per byte loss and corruption.
//   5. Receiving radio: the packet is delivered `latency` after it ends, then written to the host at baud/10.
//   6. Optional USB serial adapter at the receiving host (usb_latency > 0): as FTDI documents its chips
//      (AN232B-04), the adapter passes bytes on in packets of usb_packet bytes, or whatever it holds when its
//      latency timer expires; the timer restarts at every packet (16 ms is FTDI's default).
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "base/time.hpp"
#include "tools/linksim/radio_config.hpp"

namespace airseg::linksim {

/// Counters for one direction, named by the sending side.
struct DirectionStats {
    std::uint64_t bytes_in = 0;             ///< accepted from the sending host's UART
    std::uint64_t bytes_refused = 0;        ///< offered by push() while the host UART buffer was full
    std::uint64_t bytes_out = 0;            ///< delivered to the receiving host
    std::uint64_t overflow_dropped = 0;     ///< arrived at a full radio FIFO
    std::uint64_t rx_overflow_dropped = 0;  ///< arrived at a full receiving-radio output buffer
    std::uint64_t bytes_lost = 0;           ///< removed by byte loss
    std::uint64_t bytes_corrupted = 0;      ///< delivered with at least one flipped bit
    std::uint64_t packets_sent = 0;         ///< air packets transmitted
    std::uint64_t packets_lost = 0;         ///< air packets removed by frame loss
    std::uint64_t outage_packets_lost = 0;  ///< air packets lost to an outage or a radio that is down
    std::uint64_t down_dropped = 0;         ///< bytes written to a radio that was down
    Duration air_time{0};                   ///< air occupied by this direction's packets (without turnaround)
};

class RadioModel {
  public:
    /// `start` anchors the configured outages. Throws std::invalid_argument if config.validate() fails.
    RadioModel(RadioConfig config, TimePoint start);

    std::size_t push(Side from, std::span<const std::uint8_t> bytes, TimePoint now);
    std::vector<std::uint8_t> poll_output(Side to, TimePoint now);
    TimePoint poll_timeout() const;
    std::size_t serial_space(Side from, TimePoint now);

    /// Run-time control (the emulator's control socket). Changes apply to packets that start after `now`.
    DirectionImpairment& impairment(Side from) { return config_.impairment[index(from)]; }
    void add_outage(Side from, TimePoint start, Duration length);
    /// A radio that is down accepts and drops its host's bytes, loses its FIFO, and neither sends nor
    /// receives.
    void set_radio_down(Side radio, bool down, TimePoint now);
    bool radio_down(Side radio) const { return dir(radio).down; }

    const DirectionStats& stats(Side from) const { return dir(from).stats; }
    /// Fraction of [start, now] during which the air carried packets or turnaround (half duplex: shared
    /// channel, both arguments give the same figure; full duplex: the channel of `from`).
    double air_utilisation(Side from, TimePoint now) const;
    const RadioConfig& config() const { return config_; }
    TimePoint start() const { return start_; }

  private:
    struct Timed {
        TimePoint at;
        std::uint8_t byte;
    };
    struct Interval {
        TimePoint begin;
        TimePoint end;
    };
    struct Direction {
        std::deque<Timed> serial_in;  // host→radio UART; `at` = when the byte is fully inside the radio
        TimePoint serial_in_free{};
        std::deque<std::uint8_t> fifo;
        std::deque<Timed> serial_out;  // receiving radio→host UART; `at` = when the byte leaves the UART
        TimePoint serial_out_free{};
        TimePoint adapter_sent{};  // the receiving host's USB adapter: its last packet (latency timer start)
        std::vector<Interval> outages;
        std::mt19937_64 rng;
        DirectionStats stats;
        bool down = false;  // the radio on the sending side of this direction
    };
    // One air channel: both directions in half duplex, one in full duplex.
    struct Channel {
        TimePoint free_at{};
        std::optional<Side> last_sender;
        Duration busy{0};  // airtime + turnaround spent
    };

    Direction& dir(Side from) { return dirs_[index(from)]; }
    const Direction& dir(Side from) const { return dirs_[index(from)]; }
    Channel& channel_of(Side from) {
        return config_.duplex == Duplex::Half ? channels_[0] : channels_[index(from)];
    }
    const Channel& channel_of(Side from) const {
        return config_.duplex == Duplex::Half ? channels_[0] : channels_[index(from)];
    }

    struct Packet {
        TimePoint at;
        std::size_t bytes;
    };
    /// The next hand-over of bytes from direction `d` to its receiving host: the next byte alone without a
    /// USB adapter, the adapter's next packet with one. Nothing when no byte is on its way.
    std::optional<Packet> next_handover(const Direction& d, Side to) const;

    void advance(TimePoint now);
    void advance_channel(Channel& ch, std::span<const Side> senders, TimePoint now);
    void absorb(Direction& d, TimePoint until);
    std::optional<TimePoint> ready_time(const Direction& d, TimePoint free_at) const;
    void transmit(Side from, Channel& ch, TimePoint decided_at);
    void deliver(Side from, std::vector<std::uint8_t> packet, TimePoint begin, TimePoint end);
    bool in_outage(const Direction& d, TimePoint begin, TimePoint end) const;
    bool chance(Direction& d, double p);

    RadioConfig config_;
    TimePoint start_;
    TimePoint now_;
    Duration serial_byte_time_;
    double air_ns_per_byte_;
    std::array<Direction, 2> dirs_;
    std::array<Channel, 2> channels_;
};

}  // namespace airseg::linksim
