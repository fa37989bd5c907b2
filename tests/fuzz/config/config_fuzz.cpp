// Fuzzes the configuration loader with arbitrary YAML text. For any text: it is either accepted or every
// error carries a location ("source:line:col" or "--set") and a message; the loader never throws and never
// crashes; an accepted configuration loads again, unchanged, from the same text.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "daemon/config_loader.hpp"
#include "tests/fuzz/require.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace airseg::daemon;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const ConfigResult result = load_config_text(text, "fuzz.yaml");
    for (const auto& e : result.errors) {
        require(!e.message.empty());
        require(e.where.rfind("fuzz.yaml", 0) == 0);
        require(!e.to_string().empty());
    }
    if (result.ok()) {
        const ConfigResult again = load_config_text(text, "fuzz.yaml");
        require(again.ok() && diff_config(result.config, again.config).empty());
    }
    return 0;
}
