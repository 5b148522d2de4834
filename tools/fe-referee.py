#!/usr/bin/env python3
"""Finite-element referee for the FPM block cases (F1-F4) by CalculiX.

For each case and each mesh of its ladder this writes a CalculiX deck
(structured mesh of quadratic serendipity elements, the standard
neo-Hookean material, a nonlinear static step with automatic
incrementation), runs ccx when asked, and reads back the reaction on the
loaded face, the total strain energy, the Cauchy stress at the block's
centre and the displacement at a fixed lattice of reference points.  The
results go to cases/fe/CASE/ladder.csv (one row per mesh) and
lattice.csv / lattice-N<k>.csv (the lattice of the finest and the
second-finest converged mesh).

    tools/fe-referee.py --all --run          # every case, every mesh
    tools/fe-referee.py f3-extension-60 --run --ladder 2,4,8
    tools/fe-referee.py f3-extension-60 --ladder 8   # write the deck only
    tools/fe-referee.py --list                   # the cases
    tools/fe-referee.py --summary                # tables of cases/fe
    tools/fe-referee.py f4-plates-40 --run --model eighth --ladder 8 \
        --increment 0.02,0.05 --slope 3e8        # the part, steps, contact

Needs CalculiX (Debian: apt-get install calculix-ccx) and numpy.
"""

import os
import sys

# The referee lives in the package fe_referee beside this file (the case
# table, the mesh, the deck, running ccx, the results files, the
# convergence claims, the command line).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

# Also the names tools/nrmse-map.py loads from this file as a module.
from fe_referee.cases import CASES  # noqa: E402,F401
from fe_referee.ccx import last_block, read_dat  # noqa: E402,F401
from fe_referee.cli import main  # noqa: E402
from fe_referee.deck import job_name  # noqa: E402,F401
from fe_referee.mesh import make_mesh  # noqa: E402,F401

if __name__ == "__main__":
    sys.exit(main(__doc__))
