#!/usr/bin/python3
"""Writes a tiny YOLOv8-style ONNX model whose output is a known (1, 4 + C, N) table.

Usage: make_tiny_yolo.py OUT.onnx SIZE CLASSES ANCHORS ROW...
Each ROW is "anchor:cx,cy,w,h,score_0,...,score_{C-1}" (input-pixel box, class scores).
The graph is Conv(images, W=0, B=table) then Reshape, so any input gives the table: the C++
test knows exactly what the detector must decode.
"""
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper


def main(argv):
    out, size, classes, anchors = argv[1], int(argv[2]), int(argv[3]), int(argv[4])
    table = np.zeros((1, 4 + classes, anchors), dtype=np.float32)
    for row in argv[5:]:
        anchor, values = row.split(":")
        table[0, :, int(anchor)] = [float(v) for v in values.split(",")]
    k = (4 + classes) * anchors
    weights = np.zeros((k, 3, size, size), dtype=np.float32)
    nodes = [
        helper.make_node("Conv", ["images", "W", "B"], ["c"], kernel_shape=[size, size]),
        helper.make_node("Reshape", ["c", "shape"], ["output0"]),
    ]
    graph = helper.make_graph(
        nodes, "tiny_yolo",
        [helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, size, size])],
        [helper.make_tensor_value_info("output0", TensorProto.FLOAT, [1, 4 + classes, anchors])],
        initializer=[numpy_helper.from_array(weights, "W"), numpy_helper.from_array(table.reshape(k), "B"),
                     numpy_helper.from_array(np.array([1, 4 + classes, anchors], dtype=np.int64), "shape")])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 7
    onnx.checker.check_model(model)
    onnx.save(model, out)


if __name__ == "__main__":
    main(sys.argv)
