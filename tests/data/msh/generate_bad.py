#!/usr/bin/python3
"""Writes the broken .msh files of tests/cli/bad_input_msh.cmake into bad/ (a one-tet mesh
broken in one way each). Run: /usr/bin/python3 tests/data/msh/generate_bad.py"""
import os
import struct

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bad")
os.makedirs(out, exist_ok=True)

HDR = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
NODES = "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
ELEMS = "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"
ascii = {
    "truncated": HDR + NODES + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2",
    "wrong_count": HDR + NODES.replace("1 4 1 4\n", "1 5 1 5\n") + ELEMS,
    "node_undefined": HDR + NODES + ELEMS.replace("1 1 2 3 4", "1 1 2 3 99"),
    "nan_coord": HDR + NODES.replace("1 0 0\n", "1 nan 0\n") + ELEMS,
    "unknown_type": HDR + NODES + ELEMS.replace("3 1 4 1", "3 1 999 1"),
    "version30": HDR.replace("4.1", "3.0") + NODES + ELEMS,
    "version40": HDR.replace("4.1", "4.0") + NODES + ELEMS,
    "partitioned": HDR + "$PartitionedEntities\n1\n0\n$EndPartitionedEntities\n" + NODES + ELEMS,
    "v22_wrong_count": "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n"
                       "3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n2\n1 4 2 0 1 1 2 3 4\n$EndElements\n",
}
for name, text in ascii.items():
    with open(os.path.join(out, name + ".msh"), "w") as f:
        f.write(text)


def binary41(marker=b"\x01\x00\x00\x00", num_nodes=4, cut=0):
    q = lambda *v: struct.pack("<%dQ" % len(v), *v)
    i = lambda *v: struct.pack("<%di" % len(v), *v)
    b = b"$MeshFormat\n4.1 1 8\n" + marker + b"\n$EndMeshFormat\n$Nodes\n"
    b += q(1, num_nodes, 1, 4) + i(3, 1, 0) + q(4) + q(1, 2, 3, 4)
    b += struct.pack("<12d", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1) + b"\n$EndNodes\n$Elements\n"
    b += q(1, 1, 1, 1) + i(3, 1, 4) + q(1) + q(1, 1, 2, 3, 4) + b"\n$EndElements\n"
    return b[:len(b) - cut] if cut else b


with open(os.path.join(out, "big_endian.msh"), "wb") as f:
    f.write(binary41(marker=b"\x00\x00\x00\x01"))
with open(os.path.join(out, "binary_count.msh"), "wb") as f:
    f.write(binary41(num_nodes=1 << 40))
with open(os.path.join(out, "binary_truncated.msh"), "wb") as f:
    f.write(binary41(cut=30))  # inside the element record
with open(os.path.join(out, "ok_binary.msh"), "wb") as f:
    f.write(binary41())
