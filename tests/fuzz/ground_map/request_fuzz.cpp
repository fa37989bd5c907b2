// Fuzzes the map's request reading (Beast's parser under the map's limits, ground/map/request_reader.hpp)
// with arbitrary bytes, fed in chunks of the size the first byte picks, the requests taken one after another
// as the server takes pipelined ones. For any bytes: nothing crashes or throws; every request taken has a
// method, a path from / without a NUL, HTTP/1.0 or 1.1, at most the headers and body bytes allowed; a refusal
// has a status the server answers with and a reason; and no more requests are taken than the bytes could
// hold.
#include <cstdint>
#include <string_view>

#include "ground/map/request_reader.hpp"
#include "tests/fuzz/require.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using airseg::ground::http::Limits;
    using airseg::ground::http::RequestReader;
    if (size == 0) {
        return 0;
    }
    const std::size_t chunk = 1 + data[0] % 64;
    std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
    const Limits limits{1024, 8, 256, 4096};
    RequestReader reader(limits);
    std::size_t taken = 0;
    auto state = reader.feed({});
    for (;;) {
        while (state == RequestReader::State::Done) {
            const auto req = reader.take();
            ++taken;
            require(taken <= size / 16 + 1);  // "GET / HTTP/1.0\r\n\r\n" is the shortest: 18 bytes
            require(!req.method.empty());
            require(req.path.starts_with('/'));
            require(req.path.find('\0') == std::string::npos);
            require(req.version == 10 || req.version == 11);
            require(req.headers.size() <= limits.headers);
            require(req.body.size() <= limits.body_bytes);
            require(req.version == 10 || req.header("host"));
            state = reader.feed({});
        }
        if (state == RequestReader::State::Failed) {
            const int status = reader.error_status();
            require(status == 400 || status == 413 || status == 414 || status == 431 || status == 501 ||
                    status == 505);
            require(!reader.error().empty());
            require(reader.feed("GET / HTTP/1.1\r\n\r\n") == RequestReader::State::Failed);
            return 0;
        }
        if (rest.empty()) {
            return 0;
        }
        const auto next = rest.substr(0, chunk);
        rest.remove_prefix(next.size());
        state = reader.feed(next);
    }
}
