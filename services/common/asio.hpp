#pragma once
// Boost.Asio for the services, through the HAL's single include (which carries the Boost 1.74 + GCC 12 fix).
#include "hal/asio.hpp"

namespace airseg {
namespace asio = boost::asio;
using Strand = asio::strand<asio::io_context::executor_type>;
}  // namespace airseg
