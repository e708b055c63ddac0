"""The joint-naming schemes that ``likeme profile`` recognises, written as data: one table per scheme.

Each :class:`Scheme` maps likeme's parts (the left side only: the right side's names are mirrored,
``likeme.profiles._mirror``) to the scheme's joints in order of preference. A joint is a name, compared in lower
case without a ``prefix:`` (``mixamorig:``) or separators (so ``hip_center`` is ``HipCenter``), or a tuple of names
whose mean is the part (MediaPipe has no pelvis: its root is the mean of its hips). A scheme also says what it knows
about its recordings: units known for it (CMU's own unit), whether its joints are a person's (whose height tells the
units), and whether it records in a camera's frame (the floor is not at the origin).

Adding a scheme is adding a table here; ``tests/likeme/test_proposer.py`` writes a small made-up file of each one
and checks the root, units and parts proposed for it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["Scheme", "SCHEMES", "CMU_UNIT"]

CMU_UNIT = 0.0254 / 0.45
"""Metres per unit of the CMU motion-capture library's ASF/AMC files, kept by cgspeed's BVH conversions (the ASF
``length`` of 0.45 of an inch): about 0.056444 m."""

Candidate = str | tuple[str, ...]


@dataclass(frozen=True)
class Scheme:
    """A joint-naming scheme: its parts and what is known of its recordings.

    Attributes
    ----------
    name : str
    parts : mapping of str to tuple of Candidate
        likeme part -> the scheme's joints that can be it, in order of preference (a tuple of names: their mean).
    units : tuple of (float, str)
        Metres per unit known for the scheme, each with the comment the proposal writes beside it; tried before the
        usual units (metre, centimetre, millimetre, inch).
    person : bool
        Its joints are a person's: the height from the head to the feet tells the units.
    camera : bool
        It records in a camera's frame: the floor is wherever the camera puts it (a proposal finds it).
    """

    name: str
    parts: Mapping[str, tuple[Candidate, ...]]
    units: tuple[tuple[float, str], ...] = ()
    person: bool = True
    camera: bool = False


BANDAI_NAMCO = Scheme("Bandai-Namco", {
    "root": ("Hips",), "chest": ("Chest",), "neck": ("Neck",), "head": ("Head",), "head_top": ("Head_end",),
    "left_shoulder": ("UpperArm_L",), "left_elbow": ("LowerArm_L",), "left_wrist": ("Hand_L",),
    "left_hand": ("Hand_L_end",), "left_hip": ("UpperLeg_L",), "left_knee": ("LowerLeg_L",),
    "left_foot": ("Foot_L",), "left_toes": ("Toes_L",), "left_toe_tip": ("Toes_L_end",),
}, units=((0.01, "centimetres, as the Bandai-Namco research datasets are written"),))

MIXAMO = Scheme("Mixamo", {
    "root": ("mixamorig:Hips",), "chest": ("mixamorig:Spine2", "mixamorig:Spine1"), "neck": ("mixamorig:Neck",),
    "head": ("mixamorig:Head",), "head_top": ("mixamorig:HeadTop_End", "mixamorig:Head_end"),
    "left_shoulder": ("mixamorig:LeftArm",), "left_elbow": ("mixamorig:LeftForeArm",),
    "left_wrist": ("mixamorig:LeftHand",), "left_hip": ("mixamorig:LeftUpLeg",), "left_knee": ("mixamorig:LeftLeg",),
    "left_foot": ("mixamorig:LeftFoot",), "left_toes": ("mixamorig:LeftToeBase",),
    "left_toe_tip": ("mixamorig:LeftToe_End", "mixamorig:LeftToeBase_end"),
})

CMU_MOTIONBUILDER = Scheme("CMU (cgspeed, MotionBuilder names)", {
    # LeftShoulder is the collar bone here, LeftArm the shoulder joint; LHipJoint sits on the hips
    "root": ("Hips",), "chest": ("Spine1", "Spine"), "neck": ("Neck1", "Neck"), "head": ("Head",),
    "head_top": ("Head_end",), "left_shoulder": ("LeftArm",), "left_elbow": ("LeftForeArm",),
    "left_wrist": ("LeftHand",), "left_hand": ("LeftFingerBase", "LeftHandIndex1"), "left_hip": ("LeftUpLeg",),
    "left_knee": ("LeftLeg",), "left_foot": ("LeftFoot",), "left_toes": ("LeftToeBase",),
    "left_toe_tip": ("LeftToeBase_end",),
}, units=((CMU_UNIT, "CMU's own unit (1/0.45 inch), kept by cgspeed's conversions"),))

CMU_3DSMAX = Scheme("CMU (cgspeed, 3dsMax names)", {
    # LeftShoulder is the shoulder joint here, LeftCollar the collar bone
    "root": ("Hips",), "chest": ("Chest2", "Chest"), "neck": ("Neck",), "head": ("Head",), "head_top": ("Head_end",),
    "left_shoulder": ("LeftShoulder",), "left_elbow": ("LeftElbow",), "left_wrist": ("LeftWrist",),
    "left_hip": ("LeftHip",), "left_knee": ("LeftKnee",), "left_foot": ("LeftAnkle",), "left_toes": ("LeftToe",),
    "left_toe_tip": ("LeftToe_end",),
}, units=((CMU_UNIT, "CMU's own unit (1/0.45 inch), kept by cgspeed's conversions"),))

KINECT_V1 = Scheme("Kinect v1", {
    # the SDK's JointType names (HipCenter, ShoulderLeft) and the snake_case of CSV exporters (hip_center,
    # left_shoulder)
    "root": ("HipCenter",), "chest": ("ShoulderCenter",), "head": ("Head",),
    "left_shoulder": ("ShoulderLeft", "left_shoulder"), "left_elbow": ("ElbowLeft", "left_elbow"),
    "left_wrist": ("WristLeft", "left_wrist"), "left_hand": ("HandLeft", "left_hand"),
    "left_hip": ("HipLeft", "left_hip"), "left_knee": ("KneeLeft", "left_knee"),
    "left_foot": ("AnkleLeft", "left_ankle"), "left_toes": ("FootLeft", "left_foot"),
}, camera=True)

KINECT_V2 = Scheme("Kinect v2", {
    # the SDK's JointType names; Azure Kinect's (PELVIS, SPINE_CHEST, SHOULDER_LEFT) where they differ
    "root": ("SpineBase", "PELVIS"), "chest": ("SpineShoulder", "SPINE_CHEST"), "neck": ("Neck",),
    "head": ("Head",), "nose": ("NOSE",), "left_shoulder": ("ShoulderLeft",), "left_elbow": ("ElbowLeft",),
    "left_wrist": ("WristLeft",), "left_hand": ("HandLeft",), "left_hand_tip": ("HandTipLeft",),
    "left_hip": ("HipLeft",), "left_knee": ("KneeLeft",), "left_foot": ("AnkleLeft",), "left_toes": ("FootLeft",),
}, camera=True)

MEDIAPIPE = Scheme("MediaPipe/COCO keypoints", {
    # MediaPipe Pose's 33 landmarks (left_hip, LEFT_HIP), COCO's 17, OpenPose's BODY_25 (LHip, MidHip); none but
    # OpenPose has a pelvis or a chest: they are the means of the hips and of the shoulders
    "root": ("MidHip", "mid_hip", "pelvis", ("left_hip", "right_hip"), ("LHip", "RHip")),
    "chest": ("Neck", ("left_shoulder", "right_shoulder"), ("LShoulder", "RShoulder")),
    "head": (("left_ear", "right_ear"), ("LEar", "REar")), "nose": ("nose", "Nose"),
    "left_eye": ("left_eye", "LEye"), "left_ear": ("left_ear", "LEar"),
    "left_shoulder": ("left_shoulder", "LShoulder"), "left_elbow": ("left_elbow", "LElbow"),
    "left_wrist": ("left_wrist", "LWrist"), "left_hand": ("left_index", "left_pinky"),
    "left_hip": ("left_hip", "LHip"), "left_knee": ("left_knee", "LKnee"), "left_foot": ("left_ankle", "LAnkle"),
    "left_heel": ("left_heel", "LHeel"), "left_toes": ("left_foot_index", "LBigToe"),
}, camera=True)

SCHEMES: dict[str, Scheme] = {s.name: s for s in (BANDAI_NAMCO, MIXAMO, CMU_MOTIONBUILDER, CMU_3DSMAX, KINECT_V1,
                                                   KINECT_V2, MEDIAPIPE)}
"""Every scheme a proposal knows, by name."""
