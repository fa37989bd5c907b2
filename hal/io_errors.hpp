#pragma once
// Classification of descriptor errors shared by the serial port and the pty.
#include <cerrno>

#include "hal/asio.hpp"

namespace airseg::hal {

/// True when an error means the device itself is gone (USB unplugged, pty peer hung up), as opposed to a
/// transient or programming error: EIO, ENODEV, ENXIO, or end of file on a tty.
inline bool is_unplug_error(const boost::system::error_code& ec) {
    if (ec == boost::asio::error::eof) {
        return true;
    }
    if (ec.category() != boost::system::system_category()) {
        return false;
    }
    return ec.value() == EIO || ec.value() == ENODEV || ec.value() == ENXIO;
}

}  // namespace airseg::hal
