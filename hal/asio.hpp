#pragma once
// The one include for Boost.Asio in hal/ and its users.
// Boost 1.74's asio headers use std::exchange without including <utility>; under GCC 12 and -std=c++20 that
// fails to compile unless <utility> comes first, so every file reaches asio through this header.
#include <utility>

#include <boost/asio.hpp>

namespace airseg::hal {

/// Executor type every HAL object is built with; pass a strand (`boost::asio::make_strand(io)`) so that the
/// object's handlers and its owner's code never run concurrently.
using Executor = boost::asio::any_io_executor;

}  // namespace airseg::hal
