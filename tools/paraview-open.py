"""Open a pointmech run in ParaView, coloured sensibly.

    pvpython tools/paraview-open.py OUT [--field NAME] [--time T]
                                        [--screenshot FILE.png] [--state FILE.pvsm]

Reads OUT/results.xdmf (every frame a time step) and OUT/summary.json.
FPM runs are drawn deformed (the reference points and cells warped by the
displacement); MPM runs at the particles' current positions, as points.
The colour is --field, else `failed` where a membrane has it, else
`von_mises`, with its range over the shown frame.  --time picks the frame
(default the last).  --screenshot writes a picture and --state a ParaView
state file (File > Load State in the GUI reopens the same view); with
neither, the script opens an interactive window.  In the GUI's Python
shell: `import sys; sys.argv = ["", "OUT"]; exec(open("tools/paraview-open.py").read())`.
"""

import argparse
import json
import os
import sys

from paraview import simple as pv


def choose_field(reader, wanted):
    names = list(reader.PointData.keys())
    if wanted:
        if wanted not in names:
            sys.exit("paraview-open: the run has no field %r; it has %s"
                     % (wanted, ", ".join(names)))
        return wanted
    for name in ("failed", "von_mises", "displacement"):
        if name in names:
            return name
    return names[0] if names else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run", help="the run folder (pointmech run --out)")
    ap.add_argument("--field", help="the point field to colour by")
    ap.add_argument("--time", type=float, help="the time to show (default: "
                    "the last frame's)")
    ap.add_argument("--screenshot", help="write a PNG and exit")
    ap.add_argument("--state", help="write a ParaView state file and exit")
    a = ap.parse_args()
    xdmf = os.path.join(a.run, "results.xdmf")
    if not os.path.isfile(xdmf):
        sys.exit("paraview-open: no %s (is %r a run folder?)" % (xdmf, a.run))
    with open(os.path.join(a.run, "summary.json")) as f:
        summary = json.load(f)
    method = summary.get("method", "fpm")
    dim = summary.get("dimension", 3)

    reader = pv.Xdmf3ReaderS(registrationName=summary.get("name", "run"),
                             FileName=[os.path.abspath(xdmf)])
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues) or [0.0]
    t = times[-1] if a.time is None else min(times, key=lambda s: abs(s - a.time))
    reader.UpdatePipeline(t)  # the arrays are known once data is read
    field = choose_field(reader, a.field)

    shown = reader
    if method == "fpm" and "displacement" in reader.PointData.keys():
        shown = pv.WarpByVector(registrationName="deformed", Input=reader)
        shown.Vectors = ["POINTS", "displacement"]
        shown.ScaleFactor = 1.0

    view = pv.GetActiveViewOrCreate("RenderView")
    view.ViewTime = t
    scene = pv.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = t
    disp = pv.Show(shown, view)
    if method != "fpm":  # particles: points, not cells
        disp.SetRepresentationType("Points")
        disp.PointSize = 5.0
        disp.RenderPointsAsSpheres = 1
    else:
        disp.SetRepresentationType("Surface")
    if field:
        pv.ColorBy(disp, ("POINTS", field))
        disp.RescaleTransferFunctionToDataRange(False, True)
        disp.SetScalarBarVisibility(view, True)
    view.OrientationAxesVisibility = 1
    if dim == 2:
        view.InteractionMode = "2D"
        view.CameraPosition = [0, 0, 1]
        view.CameraViewUp = [0, 1, 0]
    else:
        view.CameraPosition = [1, -1.5, 1]
        view.CameraViewUp = [0, 0, 1]
    view.ResetCamera()
    pv.Render(view)
    print("paraview-open: %s, %s, %d frames, t = %g, coloured by %s"
          % (a.run, method, len(times), t, field))
    if a.screenshot:
        pv.SaveScreenshot(a.screenshot, view, ImageResolution=[1200, 900])
    if a.state:
        pv.SaveState(a.state)
    if not a.screenshot and not a.state:
        pv.Interact(view)


if __name__ == "__main__":
    main()
