// VTK legacy (.vtk) and VTK XML (.vtu) against other readers and writers: every variant meshio writes, meshio
// and the VTK library reading every file we write (skipped without those Python modules).
#include "vtk_support.hpp"

#include "tethash/io/pvd.hpp"

#include <fstream>

using namespace tethash;
using namespace tethash::test;

namespace {
// Writes a jittered grid mesh with triangles and lines around the tets in every variant meshio
// writes, plus .vtu files with appended data built by hand (meshio cannot write those).
const char* kMeshioWrite = R"PY(
import sys, os, base64, zlib
import numpy as np
import meshio
out = sys.argv[1]
nx, ny, nz = 3, 2, 2
idx = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
pts = []
for k in range(nz + 1):
    for j in range(ny + 1):
        for i in range(nx + 1):
            v = len(pts)
            pts.append([i / 3.0 + 0.01 * np.sin(1.0 + v), j * 0.1 + 0.01 * np.cos(2.0 * v), k * 2 ** 0.5 + 1e-7 * v])
pts = np.array(pts, dtype=np.float64)
kuhn = [(0, 1, 3, 7), (0, 1, 5, 7), (0, 2, 3, 7), (0, 2, 6, 7), (0, 4, 5, 7), (0, 4, 6, 7)]
tets = []
for k in range(nz):
    for j in range(ny):
        for i in range(nx):
            c = [idx(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1)) for b in range(8)]
            tets += [[c[a] for a in t] for t in kuhn]
tets = np.array(tets, dtype=np.int64)
tris = tets[:5, :3].copy()
lines = tets[:2, :2].copy()
tet_labels = 5 + np.arange(len(tets)) % 3
np.savetxt(os.path.join(out, "ref_points.txt"), pts, fmt="%.17g")
np.savetxt(os.path.join(out, "ref_tets.txt"), tets, fmt="%d")
np.savetxt(os.path.join(out, "ref_labels.txt"), tet_labels, fmt="%d")

def mesh(points):
    return meshio.Mesh(points, [("triangle", tris), ("tetra", tets), ("line", lines)],
                       point_data={"velocity": np.ones((len(points), 3)), "temp": np.arange(len(points), dtype=float)},
                       cell_data={"gmsh:physical": [np.ones(len(tris), dtype=np.int32), tet_labels.astype(np.int32),
                                                    2 * np.ones(len(lines), dtype=np.int32)]})

f32 = pts.astype(np.float32)
meshio.write(os.path.join(out, "m42_ascii.vtk"), mesh(pts), file_format="vtk42", binary=False)
meshio.write(os.path.join(out, "m42_binary.vtk"), mesh(pts), file_format="vtk42", binary=True)
meshio.write(os.path.join(out, "m42_binary_f32.vtk"), mesh(f32), file_format="vtk42", binary=True)
meshio.write(os.path.join(out, "m51_ascii.vtk"), mesh(pts), file_format="vtk", binary=False)
meshio.write(os.path.join(out, "m51_binary.vtk"), mesh(pts), file_format="vtk", binary=True)
meshio.write(os.path.join(out, "m_ascii.vtu"), mesh(pts), file_format="vtu", binary=False)
meshio.write(os.path.join(out, "m_binary.vtu"), mesh(pts), file_format="vtu", binary=True, compression=None)
meshio.write(os.path.join(out, "m_binary_f32.vtu"), mesh(f32), file_format="vtu", binary=True, compression=None)
meshio.write(os.path.join(out, "m_binary_u64.vtu"), mesh(pts), file_format="vtu", binary=True, compression=None, header_type="UInt64")
meshio.write(os.path.join(out, "z_zlib.vtu"), mesh(pts), file_format="vtu", binary=True, compression="zlib")
meshio.write(os.path.join(out, "z_zlib_u64_f32.vtu"), mesh(f32), file_format="vtu", binary=True, compression="zlib", header_type="UInt64")

# Appended data by hand: raw or base64, both byte orders, UInt32/UInt64 headers, optional zlib.
def appended(name, encoding, order, header, compress, points):
    e = "<" if order == "LittleEndian" else ">"
    h = np.dtype(e + ("u4" if header == "UInt32" else "u8"))
    ncell = len(tris) + len(tets)
    conn = np.concatenate([tris.ravel(), tets.ravel()]).astype(e + "i8")
    offs = np.cumsum([3] * len(tris) + [4] * len(tets)).astype(e + "i4")
    types = np.array([5] * len(tris) + [10] * len(tets), dtype=np.uint8)
    labels = np.concatenate([np.ones(len(tris)), tet_labels]).astype(e + "u2")
    arrays = [("Points", points.astype(points.dtype.newbyteorder(e)), 3), ("connectivity", conn, 1),
              ("offsets", offs, 1), ("types", types, 1), ("gmsh:physical", labels, 1)]
    blob = b""
    offsets = {}
    for aname, a, nc in arrays:
        raw = a.tobytes()
        if compress:
            bs = 64  # small blocks: several per array
            blocks = [raw[i:i + bs] for i in range(0, len(raw), bs)] or [b""]
            comp = [zlib.compress(b) for b in blocks]
            last = len(blocks[-1]) if len(blocks[-1]) < bs else 0
            hdr = np.array([len(blocks), bs, last] + [len(c) for c in comp], dtype=h).tobytes()
            data = b"".join(comp)
        else:
            hdr = np.array([len(raw)], dtype=h).tobytes()
            data = raw
        piece = hdr + data if encoding == "raw" else base64.b64encode(hdr) + base64.b64encode(data)
        offsets[aname] = len(blob)
        blob += piece
    vt = lambda a: {"f4": "Float32", "f8": "Float64", "i8": "Int64", "i4": "Int32", "u1": "UInt8", "u2": "UInt16"}[a.dtype.str[1:]]
    da = lambda aname, a, nc: ('<DataArray  Name="%s"\n NumberOfComponents="%d" format="appended" type="%s" offset="%d" />'
                               % (aname, nc, vt(a), offsets[aname]))
    comp_attr = ' compressor="vtkZLibDataCompressor"' if compress else ""
    xml = ('<?xml version="1.0"?>\n<!-- hand-made -->\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="%s" header_type="%s"%s>\n'
           '<UnstructuredGrid><Piece NumberOfCells="%d" NumberOfPoints="%d">\n<Points>%s</Points>\n<Cells>\n%s\n%s\n%s\n</Cells>\n'
           '<CellData>%s</CellData>\n</Piece></UnstructuredGrid>\n<AppendedData encoding="%s">\n   _'
           % (order, header, comp_attr, ncell, len(points), da(*arrays[0]), da(*arrays[1]), da(*arrays[2]), da(*arrays[3]),
              da(*arrays[4]), encoding))
    with open(os.path.join(out, name), "wb") as f:
        f.write(xml.encode() + blob + b"\n</AppendedData>\n</VTKFile>\n")

appended("a_raw_le.vtu", "raw", "LittleEndian", "UInt32", False, pts)
appended("a_raw_be_u64_f32.vtu", "raw", "BigEndian", "UInt64", False, f32)
appended("a_b64_le.vtu", "base64", "LittleEndian", "UInt64", False, pts)
appended("a_b64_be.vtu", "base64", "BigEndian", "UInt32", False, pts)
appended("z_raw_zlib_be.vtu", "raw", "BigEndian", "UInt32", True, pts)
appended("z_b64_zlib_le_f32.vtu", "base64", "LittleEndian", "UInt64", True, f32)
# Sanity: meshio itself reads the hand-made files.
for n in ["a_raw_le.vtu", "a_b64_le.vtu", "a_b64_be.vtu"]:
    m = meshio.read(os.path.join(out, n))
    assert len(m.points) == len(pts), n
    assert np.array_equal(m.cells_dict["tetra"], tets), n
print("ok")
)PY";

// Reads our files with meshio and compares them with the reference text files.
const char* kMeshioRead = R"PY(
import sys, os
import numpy as np
import meshio
import xml.etree.ElementTree as ET
d = sys.argv[1]
pts = np.loadtxt(os.path.join(d, "ref_points.txt")).reshape(-1, 3)
tets = np.loadtxt(os.path.join(d, "ref_tets.txt"), dtype=np.int64).reshape(-1, 4)
vel = np.loadtxt(os.path.join(d, "ref_velocity.txt")).reshape(-1, 3)
stress = np.loadtxt(os.path.join(d, "ref_stress.txt"))
objects = np.loadtxt(os.path.join(d, "ref_objects.txt"), dtype=np.int64)
def fail(msg):
    print(msg, file=sys.stderr)
    sys.exit(1)
for name in ["ours.vtu", "ours_binary.vtk", "ours_ascii.vtk"]:
    m = meshio.read(os.path.join(d, name))
    if not np.array_equal(m.points, pts): fail(name + ": points differ")
    if not np.array_equal(m.cells_dict["tetra"], tets): fail(name + ": tets differ")
    if len(m.cells) != 1: fail(name + ": expected one cell block, found %d" % len(m.cells))
    if not np.array_equal(np.asarray(m.point_data["velocity"]).reshape(-1, 3), vel): fail(name + ": velocity differs")
    c = np.asarray(m.point_data["contact"]).ravel()
    if c.shape != (len(pts),) or set(np.unique(c)) - {0.0, 1.0}: fail(name + ": contact flags wrong")
    if not np.array_equal(np.asarray(m.cell_data["stress"][0]).ravel(), stress): fail(name + ": stress differs")
    if not np.array_equal(np.asarray(m.cell_data["object"][0]).ravel(), objects): fail(name + ": object ids differ")
    if "tet_label" not in m.cell_data: fail(name + ": no tet_label")
root = ET.parse(os.path.join(d, "series.pvd")).getroot()
files = [(float(e.get("timestep")), e.get("file")) for e in root.iter("DataSet")]
if files != [(0.0, "ours.vtu"), (0.5, "ours.vtu")]: fail("pvd lists %r" % files)
print("ok")
)PY";
} // namespace

TEST(IoVtk, ReadsEveryVariantMeshioWrites)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const auto dir = temp_dir();
    write_text(dir / "write.py", kMeshioWrite);
    const RunResult r = run_shell(py + " " + quote(dir / "write.py") + " " + quote(dir));
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    const TetMesh ref = read_reference(dir);
    std::vector<Index> labels;
    {
        std::ifstream in(dir / "ref_labels.txt");
        for (Index x; in >> x;)
            labels.push_back(x);
    }
    ASSERT_EQ(ref.num_tets(), 72);
    ASSERT_EQ(labels.size(), 72u);
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string path = entry.path().string();
        const std::string name = entry.path().filename().string();
        const std::string ext = entry.path().extension().string();
        if (ext != ".vtk" && ext != ".vtu") continue;
        ++files;
        SCOPED_TRACE(name);
        if (name.rfind("z_", 0) == 0 && !io::vtu_zlib_supported()) {
            try {
                io::read_vtu(path);
                ADD_FAILURE() << "expected an error without zlib";
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find("without zlib"), std::string::npos) << e.what();
            }
            continue;
        }
        io::ReadNotes notes;
        TetMesh m;
        try {
            m = ext == ".vtk" ? io::read_vtk(path, &notes) : io::read_vtu(path, &notes);
        } catch (const Error& e) {
            ADD_FAILURE() << e.what();
            continue;
        }
        m.check_consistency(name);
        const bool f32 = name.find("f32") != std::string::npos;
        // meshio's ASCII .vtu keeps 12 significant digits.
        const double tol = f32 ? 1e-6 : name == "m_ascii.vtu" ? 1e-10 : 0;
        expect_same_mesh(ref, m, tol, name);
        EXPECT_EQ(notes.skipped_cells,
                  name.rfind("a_", 0) == 0 || name.rfind("z_raw", 0) == 0 || name.rfind("z_b64", 0) == 0 ? 5 : 7);
        EXPECT_EQ(m.tet_label, labels) << "gmsh:physical as tet labels";
    }
    EXPECT_EQ(files, 17);
}

TEST(IoVtk, MeshioReadsEveryFileWeWrite)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const auto dir = temp_dir();
    const auto [m, f] = write_ours_and_reference(dir);
    io::write_pvd((dir / "series.pvd").string(), {{0.0, "ours.vtu"}, {0.5, "ours.vtu"}});
    {
        std::ofstream v(dir / "ref_velocity.txt"), s(dir / "ref_stress.txt"), o(dir / "ref_objects.txt");
        v.precision(17);
        s.precision(17);
        for (double x : f.point[0].values)
            v << x << '\n';
        for (double x : f.cell[0].values)
            s << x << '\n';
        for (Index x : m.tet_object)
            o << x << '\n';
    }
    write_text(dir / "read.py", kMeshioRead);
    const RunResult r = run_shell(py + " " + quote(dir / "read.py") + " " + quote(dir));
    EXPECT_EQ(r.status, 0) << r.out << r.err;
}

// ---- interoperability with the VTK library itself (what ParaView uses), where python3-vtk9 is installed

namespace {
// Reads our files with VTK's own readers; writes every XML and legacy variant VTK's writers make.
const char* kVtkScript = R"PY(
import sys, os
import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy
d = sys.argv[1]
errors = []
class Watch:
    def __init__(self): self.msgs = []
    def __call__(self, obj, ev): self.msgs.append(ev)
def check_reader(r, name):
    w = Watch()
    r.AddObserver("ErrorEvent", w)
    r.AddObserver("WarningEvent", w)
    r.SetFileName(os.path.join(d, name))
    r.Update()
    if w.msgs: errors.append(name + ": VTK reported " + repr(w.msgs))
    return r.GetOutput()
pts = np.loadtxt(os.path.join(d, "ref_points.txt")).reshape(-1, 3)
tets = np.loadtxt(os.path.join(d, "ref_tets.txt"), dtype=np.int64).reshape(-1, 4)
for name in ["ours.vtu", "ours_binary.vtk", "ours_ascii.vtk"]:
    r = vtk.vtkXMLUnstructuredGridReader() if name.endswith(".vtu") else vtk.vtkUnstructuredGridReader()
    g = check_reader(r, name)
    if g.GetNumberOfPoints() != len(pts) or g.GetNumberOfCells() != len(tets):
        errors.append("%s: VTK read %d points, %d cells" % (name, g.GetNumberOfPoints(), g.GetNumberOfCells()))
        continue
    if not np.array_equal(vtk_to_numpy(g.GetPoints().GetData()), pts): errors.append(name + ": points differ")
    for c in range(len(tets)):
        ids = g.GetCell(c).GetPointIds()
        if g.GetCellType(c) != 10 or [ids.GetId(k) for k in range(4)] != list(tets[c]):
            errors.append(name + ": cell %d differs" % c)
            break
    for arr in ["velocity", "contact", "object"]:
        if g.GetPointData().GetArray(arr) is None: errors.append(name + ": no point array " + arr)
    for arr in ["stress", "object", "tet_label"]:
        if g.GetCellData().GetArray(arr) is None: errors.append(name + ": no cell array " + arr)
    if g.GetPointData().GetArray("velocity") is not None and g.GetPointData().GetArray("velocity").GetNumberOfComponents() != 3:
        errors.append(name + ": velocity is not a 3-vector")
# VTK writes the same mesh with a triangle in front and labels as cell data.
grid = vtk.vtkUnstructuredGrid()
p = vtk.vtkPoints()
p.SetData(numpy_to_vtk(pts, deep=True))
grid.SetPoints(p)
ids = vtk.vtkIdList()
for k in range(3): ids.InsertNextId(int(tets[0][k]))
grid.InsertNextCell(5, ids)
for t in tets:
    ids = vtk.vtkIdList()
    for k in range(4): ids.InsertNextId(int(t[k]))
    grid.InsertNextCell(10, ids)
lab = numpy_to_vtk(np.concatenate([[0], 5 + np.arange(len(tets)) % 3]).astype(np.int32), deep=True)
lab.SetName("tet_label")
grid.GetCellData().AddArray(lab)
for mode in ["ascii", "binary", "appended", "appended_b64"]:
    for comp in ["none", "zlib"]:
        for header in [32, 64]:
            for order in ["le", "be"]:
                if mode == "ascii" and (comp != "none" or header != 32 or order != "le"): continue
                w = vtk.vtkXMLUnstructuredGridWriter()
                w.SetInputData(grid)
                name = "vtk_%s_%s_%d_%s.vtu" % (mode, comp, header, order)
                w.SetFileName(os.path.join(d, name))
                {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary}.get(mode, w.SetDataModeToAppended)()
                w.SetEncodeAppendedData(mode == "appended_b64")
                w.SetCompressorTypeToZLib() if comp == "zlib" else w.SetCompressorTypeToNone()
                w.SetHeaderTypeToUInt64() if header == 64 else w.SetHeaderTypeToUInt32()
                w.SetByteOrderToBigEndian() if order == "be" else w.SetByteOrderToLittleEndian()
                w.Write()
for version in [42, 51]:
    for binary in [False, True]:
        w = vtk.vtkUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(os.path.join(d, "vtk_legacy_%d_%s.vtk" % (version, "binary" if binary else "ascii")))
        w.SetFileVersion(version)
        w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
        w.Write()
if errors:
    print("\n".join(errors), file=sys.stderr)
    sys.exit(1)
print("ok")
)PY";
} // namespace

TEST(IoVtk, VtkLibraryReadsOursAndWeReadVtkLibraryFiles)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "vtk numpy");
    const auto dir = temp_dir();
    const auto [m, f] = write_ours_and_reference(dir);
    write_text(dir / "check_with_vtk.py", kVtkScript);
    const RunResult r = run_shell(py + " " + quote(dir / "check_with_vtk.py") + " " + quote(dir));
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("vtk_", 0) != 0) continue;
        ++files;
        SCOPED_TRACE(name);
        if (name.find("zlib") != std::string::npos && !io::vtu_zlib_supported()) continue;
        io::ReadNotes notes;
        TetMesh back;
        try {
            back = entry.path().extension() == ".vtk" ? io::read_vtk(entry.path().string(), &notes)
                                                      : io::read_vtu(entry.path().string(), &notes);
        } catch (const Error& e) {
            ADD_FAILURE() << e.what();
            continue;
        }
        // VTK's legacy ASCII writer keeps about 11 significant digits; binary is exact.
        const bool ascii = name.find("ascii") != std::string::npos;
        expect_same_mesh(m, back, ascii ? 1e-9 : 0, name);
        EXPECT_EQ(notes.skipped_cells, 1);
        ASSERT_EQ(back.tet_label.size(), static_cast<std::size_t>(m.num_tets()));
        for (Index t = 0; t < m.num_tets(); ++t)
            ASSERT_EQ(back.tet_label[static_cast<std::size_t>(t)], 5 + t % 3);
    }
    EXPECT_EQ(files, 1 + 3 * 2 * 2 * 2 + 4);
}
