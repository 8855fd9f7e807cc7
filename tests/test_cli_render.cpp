// tethash render and simulate --render: pictures of a run (a PNG that decodes, a GIF with one image per frame), the
// static obstacles written beside the frames and listed by the series, and the refusals: a missing input, a bad
// output name, a folder that does not exist (status 2), a folder that takes no file (status 1), nothing half-written.
#include "render_support.hpp"
#include "support.hpp"

#include <filesystem>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

// A box dropped into an open bowl-like obstacle (a closed box surface as a bsp collider) over the ground.
const char* kScene = R"(dt = 2e-3
steps = 6
[ground]
height = 0.0
[output]
every = 2
[[object]]
generate = { shape = "box", resolution = 2, size = 0.3 }
translate = [0, 0, 0.5]
[[object]]
name = "block"
mesh = "block.obj"
collider = "bsp"
static = true
)";

// A closed box surface, 1 × 1 × 0.2, beside the body (x from 1 to 2).
const char* kBlockObj = R"(v 1 -0.5 0
v 2 -0.5 0
v 2 0.5 0
v 1 0.5 0
v 1 -0.5 0.2
v 2 -0.5 0.2
v 2 0.5 0.2
v 1 0.5 0.2
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
)";

fs::path run_scene(const fs::path& dir, const std::string& extra = "")
{
    write_text(dir / "s.toml", kScene);
    write_text(dir / "block.obj", kBlockObj);
    const auto r = run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out") + " " + extra);
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    return dir / "out";
}

} // namespace

TEST(CliRender, TheObstaclesAndTheGroundAreWrittenAndListedBesideTheFrames)
{
    const auto dir = temp_dir();
    const fs::path out = run_scene(dir);
    ASSERT_TRUE(fs::exists(out / "static.vtu"));
    const std::string pvd = read_text(out / "scene.pvd");
    // Each of the 4 times lists its frame (part 0) and the static surface (part 1).
    std::size_t at = 0;
    int statics = 0;
    while ((at = pvd.find("part=\"1\" file=\"static.vtu\"", at)) != std::string::npos)
        ++statics, ++at;
    EXPECT_EQ(statics, 4) << pvd;
    EXPECT_NE(pvd.find("part=\"0\" file=\"frame_00006.vtu\""), std::string::npos) << pvd;
    // The surface: the block's 12 triangles (object 1, after the one tet object) and the ground's 2 (object -1).
    const tethash::io::VtuContents c = tethash::io::read_vtu_contents((out / "static.vtu").string());
    EXPECT_EQ(c.mesh.num_tets(), 0);
    ASSERT_EQ(c.triangles.rows(), 14);
    ASSERT_EQ(c.fields.cell.size(), 1u);
    EXPECT_EQ(c.fields.cell[0].name, "object");
    int block = 0, ground = 0;
    for (double v : c.fields.cell[0].values)
        block += v == 1, ground += v == -1;
    EXPECT_EQ(block, 12);
    EXPECT_EQ(ground, 2);
    // The run says its up axis for the camera.
    EXPECT_NE(read_text(out / "run.json").find("\"up\": [0, 0, 1]"), std::string::npos);
}

TEST(CliRender, DrawsAPngOfARunAndAGifWithOneImagePerFrame)
{
    const auto dir = temp_dir();
    const fs::path out = run_scene(dir);
    for (const std::string& input : {out.string(), (out / "scene.pvd").string(), (out / "frame_00004.vtu").string()}) {
        const auto r = run_tethash("render " + quote(input) + " -o " + quote(dir / "a.png") + " --size 320x200");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.out.find("wrote"), std::string::npos);
        const Png png = decode_png(read_text(dir / "a.png"));
        EXPECT_TRUE(png.ok);
        EXPECT_EQ(png.width, 320);
        EXPECT_EQ(png.height, 200);
    }
    // A strip of the frames nearest three times: three panels side by side.
    const auto strip =
        run_tethash("render " + quote(out) + " -o " + quote(dir / "s.png") + " --size 100x80 --times 0,0.004,0.012");
    ASSERT_EQ(strip.status, 0) << strip.err;
    const Png s = decode_png(read_text(dir / "s.png"));
    EXPECT_EQ(s.width, 300);
    EXPECT_EQ(s.height, 80);
    const auto r = run_tethash("render " + quote(out) + " -o " + quote(dir / "a.gif") +
                               " --size 160x120 --field penetration_depth");
    ASSERT_EQ(r.status, 0) << r.err;
    const GifFile g = parse_gif(read_text(dir / "a.gif"));
    ASSERT_TRUE(g.valid) << g.error;
    EXPECT_EQ(g.width, 160);
    EXPECT_EQ(g.height, 120);
    EXPECT_EQ(g.images.size(), 4u); // frames at steps 0, 2, 4, 6
    const auto every =
        run_tethash("render " + quote(out) + " -o " + quote(dir / "b.gif") + " --size 160x120 --every 2");
    ASSERT_EQ(every.status, 0) << every.err;
    EXPECT_EQ(parse_gif(read_text(dir / "b.gif")).images.size(), 2u);
}

TEST(CliRender, SimulateRenderWritesTheAnimationAtTheEnd)
{
    const auto dir = temp_dir();
    const fs::path out = run_scene(dir, "--render --size 96x64");
    const GifFile g = parse_gif(read_text(out / "scene.gif"));
    ASSERT_TRUE(g.valid) << g.error;
    EXPECT_EQ(g.images.size(), 4u);
    EXPECT_EQ(g.width, 96);
    // A bad --render name is refused before the run: no frame written.
    write_text(dir / "s.toml", kScene);
    const auto r =
        run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out2") + " --render x.jpg");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--render 'x.jpg'"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out2" / "frame_00000.vtu"));
    // A scene that writes no frames has nothing to draw: said before the run.
    std::string none = kScene;
    none.replace(none.find("every = 2"), 9, "every = 0");
    write_text(dir / "none.toml", none);
    const auto n = run_tethash("simulate " + quote(dir / "none.toml") + " --out " + quote(dir / "out3") + " --render");
    EXPECT_EQ(n.status, 2);
    EXPECT_NE(n.err.find("writes no frames"), std::string::npos) << n.err;
    EXPECT_EQ(n.out.find("steps:"), std::string::npos) << n.out;
}

TEST(CliRender, BadInputExits2AndAFolderThatTakesNoFileExits1)
{
    const auto dir = temp_dir();
    const fs::path out = run_scene(dir);
    struct Case {
        std::string args;
        std::vector<std::string> says;
        int status;
    };
    const std::string run = quote(out);
    const std::vector<Case> cases = {
        {quote(dir / "missing") + " -o " + quote(dir / "x.png"), {"missing", "no such file"}, 2},
        {quote(dir / "s.toml") + " -o " + quote(dir / "x.png"), {"s.toml", "expected a run folder"}, 2},
        {quote(dir) + " -o " + quote(dir / "x.png"), {"no scene.pvd"}, 2},
        {run + " -o " + quote(dir / "x.jpg"), {"x.jpg", ".png, .gif or .mp4"}, 2},
        {run + " -o " + quote(dir / "no" / "x.png"), {"x.png"}, 2},
        {run + " -o " + quote(dir / "x.png") + " --size 10x10", {"--size", "16 to 8192"}, 2},
        {run + " -o " + quote(dir / "x.png") + " --size big", {"--size", "WxH"}, 2},
        {run + " -o " + quote(dir / "x.png") + " --elevation 95", {"--elevation"}, 2},
        {run + " -o " + quote(dir / "x.png") + " --field pressure", {"no point or cell array 'pressure'"}, 2},
        {run + " -o " + quote(dir / "x.png") + " --field contact --range 1,0", {"--range"}, 2},
        {run + " -o /proc/tethash_render.png", {"/proc"}, 1},
    };
    for (const Case& c : cases) {
        const auto r = run_tethash("render " + c.args);
        EXPECT_EQ(r.status, c.status) << c.args << "\n" << r.err;
        for (const std::string& s : c.says)
            EXPECT_NE(r.err.find(s), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_FALSE(fs::exists(dir / "x.png")) << c.args;
    }
    // A frame listed by the series but missing: named.
    fs::remove(out / "frame_00002.vtu");
    const auto r = run_tethash("render " + run + " -o " + quote(dir / "x.png"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("frame_00002.vtu"), std::string::npos) << r.err;
    // Without ffmpeg on PATH, an .mp4 is refused with the reason (and a .gif suggested).
    const auto mp4 = run_shell("PATH=/nonexistent " + quote(TETHASH_EXE) + " render " +
                               quote(dir / "out" / "scene.pvd") + " -o " + quote(dir / "x.mp4"));
    EXPECT_EQ(mp4.status, 2);
    EXPECT_NE(mp4.err.find("ffmpeg"), std::string::npos) << mp4.err;
    EXPECT_FALSE(fs::exists(dir / "x.mp4"));
}

// An .mp4 goes through the ffmpeg program: the raw frames reach it on its standard input and the file it writes is
// renamed into place; an ffmpeg that fails leaves nothing (status 1). A stand-in ffmpeg (a shell script) plays it.
TEST(CliRender, Mp4FramesGoThroughFfmpegAndItsFailureLeavesNothing)
{
    const auto dir = temp_dir();
    const fs::path out = run_scene(dir);
    fs::create_directories(dir / "bin");
    write_text(dir / "bin" / "ffmpeg", "#!/bin/sh\nfor last; do :; done\ncat > \"$last\"\n");
    fs::permissions(dir / "bin" / "ffmpeg", fs::perms::owner_all);
    const std::string path = "PATH=" + quote(dir / "bin") + ":/usr/bin:/bin ";
    const auto r = run_shell(path + quote(TETHASH_EXE) + " render " + quote(out) + " -o " + quote(dir / "x.mp4") +
                             " --size 96x64");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(fs::file_size(dir / "x.mp4"), 4u * 96 * 64 * 3); // 4 frames of raw RGB
    const auto odd = run_shell(path + quote(TETHASH_EXE) + " render " + quote(out) + " -o " + quote(dir / "y.mp4") +
                               " --size 95x64");
    EXPECT_EQ(odd.status, 2);
    EXPECT_NE(odd.err.find("even"), std::string::npos) << odd.err;
    write_text(dir / "bin" / "ffmpeg", "#!/bin/sh\ncat > /dev/null\necho 'ffmpeg: no encoder' >&2\nexit 1\n");
    const auto bad = run_shell(path + quote(TETHASH_EXE) + " render " + quote(out) + " -o " + quote(dir / "y.mp4") +
                               " --size 96x64");
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.err.find("ffmpeg failed"), std::string::npos) << bad.err;
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find("y.mp4"), std::string::npos) << e.path();
}
