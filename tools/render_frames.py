#!/usr/bin/env python3
"""Render .vtu frames of a tethash simulation side by side into one PNG (a quick look without ParaView).

Usage: tools/render_frames.py FRAME.vtu [FRAME.vtu ...] -o OUT.png [--width 1200] [--height 400]

Needs VTK's Python module (Debian: python3-vtk9) and, without a display, xvfb-run:
    xvfb-run -a /usr/bin/python3 tools/render_frames.py out/frame_00000.vtu out/frame_00400.vtu -o look.png
Objects are coloured by the cell field "object"; the camera looks along +y at the union of all frames' bounds,
with z up, the same for every frame, so motion between frames is visible.
"""
import argparse
import sys

try:
    import vtk
except ImportError:
    sys.exit("render_frames.py: this Python has no 'vtk' module (Debian: apt-get install python3-vtk9)")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("frames", nargs="+")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--width", type=int, default=1200)
    ap.add_argument("--height", type=int, default=400)
    args = ap.parse_args()

    readers, bounds = [], [float("inf"), float("-inf")] * 3
    for f in args.frames:
        r = vtk.vtkXMLUnstructuredGridReader()
        r.SetFileName(f)
        r.Update()
        if r.GetOutput().GetNumberOfPoints() == 0:
            sys.exit(f"render_frames.py: {f}: no points (not a readable .vtu?)")
        b = r.GetOutput().GetBounds()
        for k in range(3):
            bounds[2 * k] = min(bounds[2 * k], b[2 * k])
            bounds[2 * k + 1] = max(bounds[2 * k + 1], b[2 * k + 1])
        readers.append(r)
    centre = [(bounds[2 * k] + bounds[2 * k + 1]) / 2 for k in range(3)]
    extent = max(bounds[2 * k + 1] - bounds[2 * k] for k in range(3))

    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(args.width, args.height)
    n = len(readers)
    for i, r in enumerate(readers):
        surface = vtk.vtkDataSetSurfaceFilter()
        surface.SetInputConnection(r.GetOutputPort())
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputConnection(surface.GetOutputPort())
        objects = r.GetOutput().GetCellData().GetArray("object")
        if objects is not None:
            mapper.SetScalarModeToUseCellFieldData()
            mapper.SelectColorArray("object")
            mapper.SetScalarRange(objects.GetRange())
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().EdgeVisibilityOn()
        ren = vtk.vtkRenderer()
        ren.SetBackground(1, 1, 1)
        ren.SetViewport(i / n, 0, (i + 1) / n, 1)
        ren.AddActor(actor)
        cam = ren.GetActiveCamera()
        cam.SetFocalPoint(*centre)
        cam.SetPosition(centre[0], centre[1] - 3.0 * extent, centre[2] + 0.6 * extent)
        cam.SetViewUp(0, 0, 1)
        win.AddRenderer(ren)
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.Update()
    png = vtk.vtkPNGWriter()
    png.SetFileName(args.out)
    png.SetInputConnection(grab.GetOutputPort())
    png.Write()
    print(f"wrote {args.out} ({n} frames)")


if __name__ == "__main__":
    main()
