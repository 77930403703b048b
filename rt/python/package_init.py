# SPDX-License-Identifier: BSD-3-Clause

# The native module (rt/python, appended by the build to lcm-gen's imports
# above): the repair on numpy arrays, PLY files, object_cloud_t decoding
# through graspfill's own decoder, and a live LCM subscriber.
from ._native import (
    Subscriber,
    decode_object_cloud,
    read_ply,
    repair,
    write_ply,
)
