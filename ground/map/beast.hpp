#pragma once
// The one include for Boost.Beast in the map: after asio's (hal/asio.hpp carries the Boost 1.74 + GCC 12
// fix).
#include "services/common/asio.hpp"

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

namespace airseg::ground {
namespace beast = boost::beast;
namespace beast_http = boost::beast::http;
}  // namespace airseg::ground
