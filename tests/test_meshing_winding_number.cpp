// meshing/winding_number.hpp: generalized winding numbers of a triangle surface.
#include "surface_support.hpp"

#include "tethash/error.hpp"
#include "tethash/meshing/winding_number.hpp"

#include <gtest/gtest.h>

using namespace tethash;
using tethash::test::sphere_surface;

TEST(WindingNumber, InsideAndOutside)
{
    const io::SurfaceMesh s = sphere_surface(8);
    const auto w = meshing::winding_numbers(s, {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.2, 0.1, -0.1),
                                                Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0.7, 0.7, 0)});
    // Far triangle groups are dipoles: a few per cent off, far from the 1/2 that decides inside.
    EXPECT_NEAR(w[0], 1.0, 0.06);
    EXPECT_NEAR(w[1], 1.0, 0.06);
    EXPECT_NEAR(w[2], 0.0, 0.06);
    EXPECT_NEAR(w[3], 0.0, 0.06);
}

TEST(WindingNumber, RejectsABadSurface)
{
    io::SurfaceMesh empty;
    EXPECT_THROW(meshing::winding_numbers(empty, {Eigen::Vector3d::Zero()}), Error);
}
