// io/file.hpp: extensions, reading a whole file, atomic writes of one file and of files that belong together.
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

using namespace tethash;
using tethash::test::expect_error;
namespace fs = std::filesystem;
using tethash::test::temp_dir;

TEST(IoFile, ExtensionIsLowerCaseWithTheDot)
{
    EXPECT_EQ(io::extension_of("a/b/Mesh.VTU"), ".vtu");
    EXPECT_EQ(io::extension_of("mesh"), "");
    EXPECT_EQ(io::extension_of("dir.d/mesh.node"), ".node");
}

TEST(IoFile, WritesAndReadsBackBytes)
{
    const auto dir = temp_dir();
    const std::string path = (dir / "bytes.bin").string();
    const std::string bytes("a\0b\r\nc", 6);
    io::write_text_file(path, bytes);
    EXPECT_EQ(io::read_file(path), bytes);
    // Nothing but the file itself is left in the folder.
    int files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++files;
    EXPECT_EQ(files, 1);
}

TEST(IoFile, ReadErrorsNameThePath)
{
    const auto dir = temp_dir();
    expect_error([&] { io::read_file(dir.string()); }, {"is a directory"});
    const std::string missing = (dir / "missing.txt").string();
    try {
        io::read_file(missing);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), missing + ": cannot open for reading");
    }
}

TEST(IoFile, FilesThatBelongTogetherAreWrittenAllOrNone)
{
    const auto dir = temp_dir();
    const std::string a = (dir / "m.node").string(), b = (dir / "m.ele").string();
    io::write_text_files({a, b}, {"node\n", "ele\n"});
    EXPECT_EQ(io::read_file(a), "node\n");
    EXPECT_EQ(io::read_file(b), "ele\n");
    // The second target is a folder: neither file changes.
    const std::string folder = (dir / "sub").string();
    fs::create_directory(folder);
    EXPECT_THROW(io::write_text_files({a, folder}, {"new\n", "new\n"}), Error);
    EXPECT_EQ(io::read_file(a), "node\n");
}

TEST(IoFile, AFailedWriteLeavesTheOldFileAndNoTemporary)
{
    const auto dir = temp_dir();
    const std::string path = (dir / "keep.txt").string();
    io::write_text_file(path, "old\n");
    EXPECT_THROW(io::write_atomically(path, [](const std::string&) { throw Error("stop"); }), Error);
    EXPECT_EQ(io::read_file(path), "old\n");
    int files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++files;
    EXPECT_EQ(files, 1);
}

// The file system refusing a file is a WriteError (a RunFailure: exit 1 in the command line), naming the target,
// never its temporary; a path that cannot name a file is bad input (Error).
TEST(IoFile, TheFileSystemRefusingAFileIsAWriteError)
{
    const auto dir = temp_dir();
    const std::string proc = "/proc/tethash_out.txt"; // procfs takes no new files, not even from root
    try {
        io::write_text_file(proc, "x\n");
        FAIL() << "no error";
    } catch (const WriteError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(proc + ": cannot create file: ", 0), 0U) << e.what();
    }
    EXPECT_THROW(io::check_output_file(proc, "--out"), WriteError);
    // A WriteError thrown on the temporary comes back as one naming the target.
    const std::string path = (dir / "keep.txt").string();
    io::write_text_file(path, "old\n");
    try {
        io::write_atomically(path, [](const std::string& tmp) { throw WriteError(tmp + ": write failed: full"); });
        FAIL() << "no error";
    } catch (const WriteError& e) {
        EXPECT_EQ(std::string(e.what()), path + ": write failed: full");
    }
    EXPECT_EQ(io::read_file(path), "old\n");
    // A regular file where the folder should be: bad input, not a WriteError.
    const std::string under_file = (dir / "keep.txt" / "out.txt").string();
    try {
        io::write_text_file(under_file, "x\n");
        FAIL() << "no error";
    } catch (const WriteError& e) {
        FAIL() << "a WriteError: " << e.what();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("is not a folder"), std::string::npos) << e.what();
    }
    int files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++files;
    EXPECT_EQ(files, 1);
}
