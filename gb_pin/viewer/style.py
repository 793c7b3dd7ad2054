"""Where each part of the scene lives in meshcat's tree, and how it looks.

Every part hangs under :data:`ROOT`, so that a viewer reused for another run clears
the whole scene with one ``delete``; meshcat's scene panel lists the parts by these
names (a user can hide the overlay, say, by its path).
"""

from __future__ import annotations

ROOT = "/meshcat/gb_pin"
ROBOT = f"{ROOT}/robot"
TRAIL = f"{ROOT}/trail"
TARGET = f"{ROOT}/target"
TARGET_SET = f"{ROOT}/targets"
OVERLAY = f"{ROOT}/overlay"

# Colours (0xRRGGBB): links orange, joints dark grey, effector and trail red, current target
# green, target grid grey, reached grid f(g(x*)) blue, postures g(x*) dark blue-grey.
LINK_COLOR = 0xE67E22
JOINT_COLOR = 0x34495E
EFFECTOR_COLOR = 0xC0392B
TARGET_COLOR = 0x27AE60
TARGET_SET_COLOR = 0x7F8C8D
GOAL_SET = f"{ROOT}/goal_set"  # the goal set, when E^X is measured on another set (eval_targets)
GOAL_SET_COLOR = 0xD63384
REACHED_COLOR = 0x2980B9
POSTURE_COLOR = 0x2C3E50
BACKGROUND_TOP = [1.0, 1.0, 1.0]
BACKGROUND_BOTTOM = [0.88, 0.90, 0.93]

# Vertical field of view of meshcat's default camera [deg] (viewer/src/index.js, create_camera).
CAMERA_FOV = 75.0
