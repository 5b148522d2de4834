"""Seeds of fuzz_pipe (tests/fuzz/fuzz_pipe.c): streams as the children of
pm_isolate.h write them (a mark, the outcome's code and message, the
result, an end mark), each after the byte that selects its reader.

    /usr/bin/python3 tests/fuzz/pipe_seeds.py DIR
"""
import os
import struct
import sys

HEAD, END = 0x706D6931, 0x706D6945


def outcome(code=0, msg=b""):
    return struct.pack("<III", HEAD, code, len(msg)) + msg


def end():
    return struct.pack("<I", END)


def array(fmt, values):
    return struct.pack("<Q", len(values)) + struct.pack("<%d%s" % (len(values), fmt), *values)


def mesh(dim, x, elem, groups):
    """gm_gmsh_isolate.c's mesh_head, then nodes, elements and groups."""
    n_nodes, n_elems = len(x) // 3, len(elem) // (dim + 1)
    s = struct.pack("<iiqqi4xd", dim, len(groups), n_nodes, n_elems, 0, 1.0)
    s += array("d", x) + array("q", elem)
    if groups:
        ptr, faces = [0], []
        for name, f in groups:
            s += array("B", list(name.encode() + b"\0"))
            faces += f
            ptr.append(len(faces) // dim)
        s += array("q", ptr) + array("q", faces)
    return s


def main(out):
    os.makedirs(out, exist_ok=True)
    tet_x = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1]
    seeds = {
        "mesh3d": bytes([0]) + outcome() + mesh(
            3, tet_x, [0, 1, 2, 3, 1, 2, 3, 4], [("base", [0, 1, 2, 1, 2, 4])]) + end(),
        "mesh2d": bytes([1]) + outcome() + mesh(
            2, [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0], [0, 1, 2, 1, 3, 2],
            [("left", [0, 2]), ("surface-7", [1, 3, 3, -1])]) + end(),
        "mesh-refused": bytes([0]) + outcome(5, b"gmsh: reading 'mesh.msh' failed") ,
        "surface": bytes([2]) + outcome() + array("d", tet_x[:12])
        + array("q", [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]) + end(),
        "bounds3d": bytes([3]) + outcome() + struct.pack("<6d", 0, 0, 0, 1, 2, 3) + end(),
        "bounds2d": bytes([4]) + outcome() + struct.pack("<6d", 0, 0, 0, 1, 2, 0) + end(),
        "probe": bytes([5]) + outcome()
        + array("d", [float(v) for v in range(24)])
        + array("d", [0.01 * v for v in range(24)]) + end(),
        "vet": bytes([6]) + outcome() + end(),
        "vet-refused": bytes([6]) + outcome(
            4, b"checkpoint.h5: HDF5 cannot read attribute format of /"),
        "torn": bytes([0]) + outcome() + mesh(3, tet_x, [0, 1, 2, 3], [])[:60],
    }
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main(sys.argv[1])
