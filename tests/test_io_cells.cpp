// Cell files (io/cells.hpp): the text written for a layout reads back as the same layout, numbers exactly; comments,
// blank lines and portal corners in either order are accepted.
#include "tethash/error.hpp"
#include "tethash/io/cells.hpp"

#include <gtest/gtest.h>

using namespace tethash;

TEST(IoCells, WrittenTextReadsBackExactly)
{
    const double lo[3] = {-0.1, 0.3, 1e-7}, hi[3] = {2.0 / 3, 1.7, 5};
    const int n[3] = {3, 1, 2};
    const CellLayout a = grid_cell_layout(lo, hi, n);
    const CellLayout b = io::parse_cells("grid.cells", io::cells_text(a));
    ASSERT_EQ(b.cells.size(), a.cells.size());
    ASSERT_EQ(b.portals.size(), a.portals.size());
    for (std::size_t k = 0; k < a.cells.size(); ++k) {
        EXPECT_EQ(b.cells[k].name, a.cells[k].name);
        for (int j = 0; j < 3; ++j) {
            EXPECT_EQ(b.cells[k].lo[j], a.cells[k].lo[j]);
            EXPECT_EQ(b.cells[k].hi[j], a.cells[k].hi[j]);
        }
    }
    for (std::size_t k = 0; k < a.portals.size(); ++k) {
        EXPECT_EQ(b.portals[k].a, a.portals[k].a);
        EXPECT_EQ(b.portals[k].b, a.portals[k].b);
        for (int j = 0; j < 3; ++j) {
            EXPECT_EQ(b.portals[k].lo[j], a.portals[k].lo[j]);
            EXPECT_EQ(b.portals[k].hi[j], a.portals[k].hi[j]);
        }
    }
}

TEST(IoCells, CommentsBlankLinesAndCornersInEitherOrder)
{
    const CellLayout l = io::parse_cells("rooms.cells", "\n# rooms\r\n  cell a 0 0 0 1 1 1  # first\r\n"
                                                        "cell b 1 0 0 2 1 1\n\nportal b a 1 0.75 1 1 0.25 0\n");
    ASSERT_EQ(l.cells.size(), 2U);
    ASSERT_EQ(l.portals.size(), 1U);
    EXPECT_EQ(l.portals[0].a, 1);
    EXPECT_EQ(l.portals[0].b, 0);
    EXPECT_EQ(l.portals[0].lo[1], 0.25);
    EXPECT_EQ(l.portals[0].hi[1], 0.75);
    EXPECT_EQ(l.portals[0].lo[2], 0);
    try {
        io::parse_cells("x.cells", "cell a 0 0 0 1 1 1\ncell b 0.5 0 0 2 1 1\n");
        ADD_FAILURE() << "overlapping cells accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("x.cells:2: cell 'b'"), std::string::npos) << e.what();
    }
}
