#pragma once
// The read and write steps shared by SerialPort and Pty. Both abandon pending I/O by bumping a generation
// counter (on close, reopen, or the pty's peer leaving) rather than waiting for it to end, so a read or a
// write that completes after that must not touch the state of the device's next life.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>

#include "hal/asio.hpp"

namespace airseg::hal {

/// Starts one async_read_some of `buffer` on `stream`. The completion keeps `self` alive and calls
/// `(self->*on_read)(gen, ec, n)` only while the read is still current: not cancelled, and
/// `self->*generation` still the `gen` it was when the read started.
template <class Owner, class Stream>
void async_read_current(Stream& stream, boost::asio::mutable_buffer buffer, std::shared_ptr<Owner> self,
                        std::uint64_t Owner::*generation,
                        void (Owner::*on_read)(std::uint64_t, boost::system::error_code, std::size_t)) {
    const std::uint64_t gen = (*self).*generation;
    stream.async_read_some(buffer, [self = std::move(self), generation, on_read, gen](
                                       boost::system::error_code ec, std::size_t n) {
        if ((*self).*generation != gen || ec == boost::asio::error::operation_aborted) {
            return;
        }
        ((*self).*on_read)(gen, ec, n);
    });
}

/// Starts one async_write of `buffers` (`size` bytes, kept alive by `keep`) on `stream`. The completion
/// calls `(self->*on_write)(ec, size)` only while the write is still current, as for a read.
template <class Owner, class Stream, class Buffers, class Keep>
void async_write_current(Stream& stream, const Buffers& buffers, Keep keep, std::size_t size,
                         std::shared_ptr<Owner> self, std::uint64_t Owner::*generation,
                         void (Owner::*on_write)(boost::system::error_code, std::size_t)) {
    const std::uint64_t gen = (*self).*generation;
    boost::asio::async_write(
        stream, buffers,
        [self = std::move(self), keep = std::move(keep), generation, on_write, gen, size](
            boost::system::error_code ec, std::size_t) {
            if ((*self).*generation != gen || ec == boost::asio::error::operation_aborted) {
                return;
            }
            ((*self).*on_write)(ec, size);
        });
}

}  // namespace airseg::hal
