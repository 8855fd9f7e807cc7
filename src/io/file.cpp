#include "tethash/io/file.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace tethash::io {

std::string extension_of(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

std::string read_file(const std::string& path)
{
    if (std::filesystem::is_directory(path)) throw Error(path + ": is a directory, expected a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw Error(path + ": read error");
    return ss.str();
}

namespace {

namespace fs = std::filesystem;

/// Folder that will hold `target` ("." for a bare file name).
fs::path folder_of(const fs::path& target)
{
    return target.has_parent_path() ? target.parent_path() : fs::path(".");
}

/// A unique hidden temporary name next to `target`.
fs::path temporary_for(const fs::path& target)
{
    static std::atomic<int> counter{0};
    std::string name = target.filename().string(); // appended piecewise: g++ 12 warns falsely on "." + string
    name.insert(name.begin(), '.');
    name.append(".tmp").append(std::to_string(::getpid())).append("_").append(std::to_string(counter++));
    return folder_of(target) / name;
}

/// `text` with every occurrence of `from` replaced by `to`.
std::string replace_all(std::string text, const std::string& from, const std::string& to)
{
    if (from.empty()) return text;
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

/// Temporary files being written, for remove_temporaries_now(): fixed slots so that a signal handler
/// can walk them without locks or allocation. A path that does not fit or finds no slot is not tracked.
struct TemporarySlot {
    std::atomic<bool> used{false};
    char path[4096] = {};
};
TemporarySlot g_temporaries[16];
std::atomic<bool> g_claimed[16];

/// Tracks `path` while alive.
class TrackedTemporary {
  public:
    explicit TrackedTemporary(const std::string& path)
    {
        if (path.size() >= sizeof(TemporarySlot::path)) return;
        for (int i = 0; i < 16; ++i) {
            bool expected = false;
            if (g_claimed[i].compare_exchange_strong(expected, true)) {
                std::memcpy(g_temporaries[i].path, path.c_str(), path.size() + 1);
                g_temporaries[i].used.store(true, std::memory_order_release);
                m_slot = i;
                return;
            }
        }
    }
    ~TrackedTemporary()
    {
        if (m_slot < 0) return;
        g_temporaries[m_slot].used.store(false, std::memory_order_release);
        g_claimed[m_slot].store(false);
    }
    TrackedTemporary(const TrackedTemporary&) = delete;
    TrackedTemporary& operator=(const TrackedTemporary&) = delete;

  private:
    int m_slot = -1;
};

void check_target(const std::string& path)
{
    const fs::path target(path);
    if (path.empty()) throw Error("empty output file name");
    if (fs::is_directory(target)) throw Error(path + ": is a directory, expected a file name");
    const fs::path dir = folder_of(target);
    if (!fs::exists(dir)) throw Error(path + ": folder '" + dir.string() + "' does not exist");
    if (!fs::is_directory(dir)) throw Error(path + ": '" + dir.string() + "' is not a folder");
}

/// Writes `text` to the file `file` (created or truncated), checking every write; messages name `path`.
void write_bytes(const std::string& file, const std::string& text, const std::string& path)
{
    std::FILE* f = std::fopen(file.c_str(), "wb");
    if (!f) throw WriteError(path + ": cannot create file: " + std::strerror(errno));
    errno = 0;
    const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    const bool flushed = std::fflush(f) == 0;
    const int err = errno;
    const bool closed = std::fclose(f) == 0;
    if (!wrote || !flushed || !closed) throw WriteError(path + ": write failed: " + std::strerror(err ? err : EIO));
}

} // namespace

void write_atomically(const std::vector<std::string>& paths,
                      const std::function<void(const std::vector<std::string>&)>& write)
{
    for (const std::string& p : paths)
        check_target(p);
    std::vector<std::string> tmps;
    for (const std::string& p : paths)
        tmps.push_back(temporary_for(p).string());
    std::vector<std::unique_ptr<TrackedTemporary>> tracked;
    for (const std::string& t : tmps)
        tracked.push_back(std::make_unique<TrackedTemporary>(t));
    // A message that names a temporary names its target instead.
    auto naming_targets = [&](std::string msg) {
        for (std::size_t i = 0; i < paths.size(); ++i)
            msg = replace_all(msg, tmps[i], paths[i]);
        return msg;
    };
    auto remove_temporaries = [&] {
        for (const std::string& t : tmps) {
            std::error_code ec;
            fs::remove(t, ec);
        }
    };
    try {
        write(tmps);
        for (std::size_t i = 0; i < paths.size(); ++i) {
            std::error_code ec;
            fs::rename(tmps[i], paths[i], ec);
            if (ec) throw WriteError(paths[i] + ": cannot move the temporary file into place: " + ec.message());
        }
    } catch (const WriteError& e) {
        remove_temporaries();
        throw WriteError(naming_targets(e.what()));
    } catch (const Error& e) {
        remove_temporaries();
        throw Error(naming_targets(e.what()));
    } catch (...) {
        remove_temporaries();
        throw;
    }
}

void remove_temporaries_now() noexcept
{
    for (auto& slot : g_temporaries)
        if (slot.used.load(std::memory_order_acquire)) ::unlink(slot.path);
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    write_atomically(std::vector<std::string>{path}, [&](const std::vector<std::string>& tmps) { write(tmps[0]); });
}

void write_text_files(const std::vector<std::string>& paths, const std::vector<std::string>& texts)
{
    write_atomically(paths, [&](const std::vector<std::string>& tmps) {
        for (std::size_t i = 0; i < tmps.size(); ++i)
            write_bytes(tmps[i], texts[i], paths[i]);
    });
}

void write_text_file(const std::string& path, const std::string& text)
{
    write_atomically(path, [&](const std::string& tmp) { write_bytes(tmp, text, path); });
}

void check_output_file(const std::string& path, const std::string& what)
{
    try {
        check_target(path);
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    // Probe the folder: permissions, read-only file systems and special folders all show up here.
    const fs::path probe = temporary_for(fs::path(path));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0)
        throw WriteError(what + ": " + path + ": cannot create files in folder '" + folder_of(fs::path(path)).string() +
                         "': " + std::strerror(errno));
    ::close(fd);
    ::unlink(probe.c_str());
}

} // namespace tethash::io
