// libFuzzer harness: the scene (TOML) loader, io-free: sim::parse_scene on the text.
#include "fuzz_support.hpp"

#include "tethash/sim/scene.hpp"

#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        tethash::sim::parse_scene(text, "fuzz.toml", ".");
    } catch (const tethash::Error&) {
    }
    return 0;
}
