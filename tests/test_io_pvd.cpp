// ParaView collections (.pvd): write and read back, names that need escaping, bad input.
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/pvd.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace tethash;
using namespace tethash::test;

TEST(IoPvd, ListsFramesInOrder)
{
    const auto dir = temp_dir();
    std::vector<std::pair<double, std::string>> frames;
    for (int i = 0; i < 3; ++i)
        frames.emplace_back(0.1 * i, "frame_" + std::to_string(i) + ".vtu");
    frames.emplace_back(1e-300, "a&b \"c\" <d>.vtu");
    io::write_pvd((dir / "series.pvd").string(), frames);
    EXPECT_EQ(io::read_pvd((dir / "series.pvd").string()), frames);
    const std::string text = read_text(dir / "series.pvd");
    EXPECT_NE(text.find("type=\"Collection\""), std::string::npos);
    EXPECT_NE(text.find("file=\"frame_2.vtu\""), std::string::npos);
    EXPECT_NE(text.find("a&amp;b &quot;c&quot; &lt;d&gt;.vtu"), std::string::npos) << text;
}

TEST(IoPvd, BadEntriesWriteNothing)
{
    const auto dir = temp_dir();
    EXPECT_THROW(io::write_pvd((dir / "bad.pvd").string(), {{std::nan(""), "x.vtu"}}), Error);
    EXPECT_THROW(io::write_pvd((dir / "bad.pvd").string(), {{0.0, ""}}), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.pvd"));
}

TEST(IoPvd, ReadErrorsNameFileAndLine)
{
    const auto dir = temp_dir();
    write_text(dir / "t.pvd", "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\">\n<Collection>\n"
                              "<DataSet timestep=\"soon\" file=\"a.vtu\"/>\n</Collection>\n</VTKFile>\n");
    expect_error([&] { io::read_pvd((dir / "t.pvd").string()); }, {"t.pvd:4: expected a number for timestep"});
    write_text(dir / "u.pvd", "<VTKFile type=\"UnstructuredGrid\"></VTKFile>\n");
    EXPECT_THROW(io::read_pvd((dir / "u.pvd").string()), Error);
}

TEST(IoPvd, PartsRoundTripAndABadPartIsNamed)
{
    const auto dir = temp_dir();
    const std::vector<io::PvdEntry> entries = {
        {0, "frame_0.vtu", 0}, {0, "static.vtu", 1}, {0.5, "frame_1.vtu", 0}, {0.5, "static.vtu", 1}};
    io::write_pvd_parts((dir / "s.pvd").string(), entries);
    const std::vector<io::PvdEntry> back = io::read_pvd_parts((dir / "s.pvd").string());
    ASSERT_EQ(back.size(), entries.size());
    for (std::size_t i = 0; i < back.size(); ++i) {
        EXPECT_EQ(back[i].time, entries[i].time);
        EXPECT_EQ(back[i].file, entries[i].file);
        EXPECT_EQ(back[i].part, entries[i].part);
    }
    EXPECT_EQ(io::read_pvd((dir / "s.pvd").string()).size(), 4u); // every part
    write_text(dir / "p.pvd", "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\">\n<Collection>\n"
                              "<DataSet timestep=\"0\" part=\"one\" file=\"a.vtu\"/>\n</Collection>\n</VTKFile>\n");
    expect_error([&] { io::read_pvd_parts((dir / "p.pvd").string()); }, {"p.pvd:4: expected a part number"});
}
