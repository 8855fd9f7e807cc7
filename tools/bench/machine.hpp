#pragma once
// What a benchmark ran on: the processor's model name, printed in every benchmark's header.
#include <fstream>
#include <string>

namespace tethash::bench {

/// The first "model name" of /proc/cpuinfo ("unknown" where there is none).
inline std::string machine_name()
{
    std::ifstream cpu("/proc/cpuinfo");
    for (std::string line; std::getline(cpu, line);)
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos && colon + 2 <= line.size()) return line.substr(colon + 2);
        }
    return "unknown";
}

} // namespace tethash::bench
