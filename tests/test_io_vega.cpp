// Vega .veg reader: hand-made files (sections skipped, both *ELEMENTS spellings, comments), bad input,
// the shared quintupleTorus mesh. meshio has no .veg format, so every file here is hand-made.
#include "io_formats_support.hpp"

#include "tethash/io/vega.hpp"

using namespace tethash;
using namespace tethash::test;

namespace {

const HandMadeFile good("# comment\n*VERTICES\n5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
                        "*ELEMENTS\nTET\n2 4 0\n1 1 2 3 4\n2 2 3 4 5\n");

} // namespace

TEST(VegaRead, HandMadeWithSkippedSections)
{
    io::ReadNotes notes;
    read_two_tets_file("vega/two_tets.veg", &notes);
    EXPECT_EQ(notes.messages.size(), 3u); // *MATERIAL, *REGION, *SET
}

TEST(VegaRead, ElementsTypeOnTheSameLineAndCommas)
{
    const auto dir = temp_dir();
    const auto p = good.edited(dir, "*ELEMENTS\nTET\n2 4 0\n1 1 2 3 4\n",
                               "*ELEMENTS TET\n2, 4, 0\n1, 1, 2, 3, 4  # first\n", "s.veg");
    expect_same_geometry(io::read_mesh(p.string()), two_tets(), "same line");
}

TEST(VegaErrors, TruncatedAndWrongCounts)
{
    const auto dir = temp_dir();
    const auto cut = good.cut(dir, "2 2 3 4 5", 6, "cut.veg");
    expect_read_error(cut, {cut.string() + ":", "vertex 3 of element 2", "found end of file"});
    expect_read_error(good.edited(dir, "5 3 0 0", "6 3 0 0", "n.veg"),
                      {at_line(dir / "n.veg", 9), "expected a vertex number (an integer), found '*ELEMENTS'"});
    expect_read_error(good.edited(dir, "1 1 2 3 4\n2 2", "1 1 2 3 4\n3 2", "id.veg"),
                      {at_line(dir / "id.veg", 13), "expected element number 2", "found 3"});
}

TEST(VegaErrors, IndexPastTheEndNanGarbage)
{
    const auto dir = temp_dir();
    expect_read_error(good.edited(dir, "2 2 3 4 5", "2 2 3 4 9", "i.veg"),
                      {at_line(dir / "i.veg", 13), "element 2: vertex index 9 is past the end (*VERTICES has 1..5)"});
    expect_read_error(good.edited(dir, "1 1 2 3 4\n", "1 0 2 3 4\n", "z.veg"),
                      {at_line(dir / "z.veg", 12), "element 1: vertex index 0 is out of range"});
    expect_read_error(good.edited(dir, "3 0 1 0", "3 0 inf 0", "inf.veg"),
                      {at_line(dir / "inf.veg", 6), "y coordinate of vertex 3 (a finite number)", "found 'inf'"});
    expect_read_error(good.edited(dir, "4 0 0 1", "4 0 0 1e", "g.veg"),
                      {at_line(dir / "g.veg", 7), "z coordinate of vertex 4", "found '1e'"});
}

TEST(VegaErrors, UnsupportedContent)
{
    const auto dir = temp_dir();
    expect_read_error(good.edited(dir, "TET", "CUBIC", "cubic.veg"),
                      {at_line(dir / "cubic.veg", 10), "expected the element type TET", "found 'CUBIC'"});
    expect_read_error(good.edited(dir, "# comment\n", "*INCLUDE other.veg\n", "inc.veg"),
                      {at_line(dir / "inc.veg", 1), "*INCLUDE is not supported"});
    expect_read_error(good.edited(dir, "# comment\n", "VERTICES\n", "kw.veg"),
                      {at_line(dir / "kw.veg", 1), "expected a section keyword such as *VERTICES", "found 'VERTICES'"});
}

TEST(VegaShared, ReadsQuintupleTorus)
{
    const auto p = shared_mesh("quintupleTorus.veg");
    if (!p) GTEST_SKIP() << "shared mesh absent";
    expect_valid_with_counts(io::read_mesh(p->string()), 15789, 71427);
}
