"""Every input a user gives fails with one clear line: file, line or key, what was expected, what is available.

``CASES`` is the table of bad inputs; ``docs/errors.md`` is generated from it with the real messages
(``python -m tests.likeme.test_errors > docs/errors.md``) and a test keeps the two equal.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import tempfile
from pathlib import Path

import pytest

from tests.conftest import STICK

ROOT = Path(__file__).resolve().parents[2]
MAX = (ROOT / "characters" / "max.toml").as_posix()

CHILD = f'[character]\nname = "Bad"\nextends = "{MAX}"\n'
BODY = STICK
SCENE = f'[scenario]\nname = "s"\n[[actors]]\nid = "max"\ncharacter = "{MAX}"\n'


BVH = """HIERARCHY
ROOT hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT head
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0
0 91 0 0 0 0 0 0 0
"""
DEEP_BVH = ("HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Xrotation Yrotation Zrotation\n"
            + "".join(f"JOINT j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Xrotation Yrotation Zrotation\n" for i in range(1, 1000))
            + "}\n" * 1000 + "MOTION\nFrames: 1\nFrame Time: 0.03\n" + " ".join(["0"] * 3000) + "\n")
"""A BVH file whose joints are nested 1,000 deep."""
PROFILE = '[profile]\nname = "p"\nunits = "cm"\n[parts]\nroot = "hips"\nhead = "head"\nnose = "head_end"\n[facing]\nleft = "head"\nright = "nose"\n'


def state(**changes):
    import json

    data = {"format": "likeme-state", "version": 1, "actors": {}}
    data.update(changes)
    return json.dumps(data)


# (case, what is wrong, files {name: text}, command arguments, fragments the one-line message must contain)
CASES = [
    # -- character files: syntax and structure
    ("toml-syntax", "TOML syntax error", {"c.toml": '[character]\nname = "X\n'}, ["validate", "c.toml"], ["c.toml:2:", "TOML syntax error"]),
    ("unknown-table", "unknown top-level table", {"c.toml": CHILD + "[sensors]\nx = 1\n"}, ["validate", "c.toml"], ["key sensors", "unknown table 'sensors'", "available: character, body, motor"]),
    ("missing-name", "character without a name", {"c.toml": f'[character]\nextends = "{MAX}"\n'}, ["validate", "c.toml"], ["key character.name", "expected a non-empty string"]),
    ("name-type", "name of the wrong type", {"c.toml": f'[character]\nname = 3\nextends = "{MAX}"\n'}, ["validate", "c.toml"], ["key character.name", "missing or invalid"]),
    ("character-key", "unknown key in [character]", {"c.toml": CHILD + 'colour = "grey"\n'}, ["validate", "c.toml"], ["key character.colour", "available: name, extends, description"]),
    ("extends-missing", "extends a file that does not exist", {"c.toml": '[character]\nname = "A"\nextends = "nobody"\n'}, ["validate", "c.toml"], ["key character.extends", "cannot find 'nobody'", "available:"]),
    ("extends-cycle", "extends cycle", {"a.toml": '[character]\nname = "A"\nextends = "b.toml"\n', "b.toml": '[character]\nname = "B"\nextends = "a.toml"\n'}, ["validate", "a.toml"], ["extends cycle: a.toml -> b.toml -> a.toml"]),
    ("missing-body", "no [body] table", {"c.toml": '[character]\nname = "A"\n[motor]\nplugin = "keyframe"\n'}, ["validate", "c.toml"], ["key body", "missing [body] table"]),
    ("parts-type", "parts is not a list", {"c.toml": BODY.replace('parts = ["root", "head", "lk", "rk"]', 'parts = "root"')}, ["validate", "c.toml"], ["key body.parts", "expected a list of part names"]),
    ("duplicate-parts", "duplicate part names", {"c.toml": BODY.replace('"lk", "rk"]', '"lk", "lk"]')}, ["validate", "c.toml"], ["key body.parts", "duplicate part names ['lk']"]),
    ("root-unknown", "root is not a part", {"c.toml": BODY.replace('root = "root"', 'root = "pelvis"')}, ["validate", "c.toml"], ["key body.root", "unknown body part 'pelvis'", "available: root, head, lk, rk"]),
    ("facing-unknown", "facing names an unknown part", {"c.toml": BODY.replace('left = "lk"', 'left = "knee"')}, ["validate", "c.toml"], ["key body.facing.left", "unknown body part 'knee'"]),
    ("bones-invalid", "a bone is not a pair", {"c.toml": BODY.replace('facing =', 'bones = [["root"]]\nfacing =')}, ["validate", "c.toml"], ["key body.bones", 'expected a list of part pairs']),
    ("colour-invalid", "a colour is not #rrggbb", {"c.toml": BODY.replace('[motor]', '[body.colours]\nhead = "red"\n[motor]')}, ["validate", "c.toml"], ["key body.colours", 'expected a table of part = "#rrggbb"']),
    ("missing-motor", "no [motor] table", {"c.toml": BODY[: BODY.index("[motor]")]}, ["validate", "c.toml"], ["key motor", "missing [motor] table"]),
    # -- plugin names and parameters
    ("motor-plugin-missing", "component table without plugin", {"c.toml": BODY.replace('plugin = "keyframe"', "")}, ["validate", "c.toml"], ["key motor.plugin", "missing or invalid plugin name", "available: keyframe, motor-command-graph, posegraph"]),
    ("motor-plugin-unknown", "unknown motor system", {"c.toml": BODY.replace('plugin = "keyframe"', 'plugin = "keyfram"')}, ["validate", "c.toml"], ["key motor.plugin", "unknown motor system 'keyfram'", "available: keyframe, motor-command-graph, posegraph"]),
    ("segmenter-unknown", "unknown segmenter", {"c.toml": CHILD + '[segmenter]\nplugin = "hub-treshold"\n'}, ["validate", "c.toml"], ["key segmenter.plugin", "unknown segmenter 'hub-treshold'", "available: hub-threshold"]),
    ("matcher-unknown", "unknown matcher", {"c.toml": CHILD + '[matcher]\nplugin = "dtwx"\n'}, ["validate", "c.toml"], ["key matcher.plugin", "unknown matcher 'dtwx'", "available: dtw, forward-model, path-search"]),
    ("perception-unknown", "unknown perception", {"c.toml": CHILD + '[perception]\nplugin = "eyes"\n'}, ["validate", "c.toml"], ["key perception.plugin", "unknown perception 'eyes'", "available: motion-capture, rendered-vision, synthetic-vision"]),
    ("param-unknown", "unknown parameter", {"c.toml": CHILD + '[segmenter]\ntreshold = 0.1\n'}, ["validate", "c.toml"], ["key segmenter.treshold", "unknown parameter 'treshold' for segmenter 'hub-threshold'", "available: body, cutoff, floor, hub"]),
    ("param-type", "parameter of the wrong type", {"c.toml": CHILD + '[matcher.beam]\nk = "eight"\n'}, ["validate", "c.toml"], ["key matcher.beam.k", "wrong type str", "expected an integer in [1, 9223372036854775807]"]),
    ("param-range", "parameter out of range", {"c.toml": CHILD + '[perception]\ndropout = 1.5\n'}, ["validate", "c.toml"], ["key perception.dropout", "value 1.5 out of range", "expected a number in [0, 1]"]),
    ("param-choice", "parameter not among the choices", {"c.toml": CHILD + '[action.tuples.satisfy_hunger]\nselect = { trigger = "object-present", kind = "food", prefer = "tastiest" }\n'}, ["validate", "c.toml"], ["key action.tuples.satisfy_hunger.select.prefer", "value 'tastiest' not allowed", "available: closest, farthest, largest"]),
    ("path-kbest-motion", "path search's beam asked to compare motion", {"c.toml": CHILD + '[matcher]\nplugin = "path-search"\ncomparison = "motion"\n'}, ["validate", "c.toml"], ["key matcher.search", "search = 'k-best' compares poses (eq. 1)", "expected search = 'per-movement' with comparison = 'motion', or comparison = 'poses'"]),
    ("needs-posegraph", "path-search without a posegraph", {"c.toml": BODY + '[matcher]\nplugin = "path-search"\n'}, ["validate", "c.toml"], ["key matcher.plugin", "path-search needs a posegraph motor system, not 'keyframe'"]),
    ("eye-unknown", "vision eye is not a part", {"c.toml": CHILD + '[perception]\neye = "eyes"\n'}, ["validate", "c.toml"], ["key perception.eye", "unknown body part 'eyes'"]),
    ("hub-param-unknown", "segmenter hub pose unknown", {"c.toml": CHILD + '[segmenter]\nhub = "sitting"\n'}, ["validate", "c.toml"], ["key segmenter.hub", "unknown hub pose 'sitting'", "available: stand"]),
    # -- the motor repertoire
    ("pose-part-unknown", "unknown part in a pose", {"c.toml": BODY.replace("shift = [0.0, -0.2, 0.0]", "shift = [0.0, -0.2, 0.0]\nnoze = [0, 1, 0]")}, ["validate", "c.toml"], ["key motor.poses.bob.noze", "unknown key 'noze'", "available: root, head, lk, rk, base, shift, offset"]),
    ("pose-incomplete", "pose without base misses parts", {"c.toml": BODY.replace('rk = [-0.1, 0.5, 0.0]\n', "")}, ["validate", "c.toml"], ["key motor.poses.stand", "pose without base misses parts ['rk']"]),
    ("pose-base-unknown", "pose base unknown", {"c.toml": BODY.replace('base = "stand"', 'base = "stnad"')}, ["validate", "c.toml"], ["key motor.poses.bob.base", "unknown pose 'stnad'", "available: bob, stand"]),
    ("pose-base-cycle", "pose bases form a cycle", {"c.toml": BODY + '[motor.poses.a]\nbase = "b"\n[motor.poses.b]\nbase = "a"\n'}, ["validate", "c.toml"], ["pose base cycle: a -> b -> a"]),
    ("pose-vector", "a position is not three numbers", {"c.toml": BODY.replace("shift = [0.0, -0.2, 0.0]", "shift = [0.0, -0.2]")}, ["validate", "c.toml"], ["key motor.poses.bob.shift", "expected [x, y, z] finite numbers in metres"]),
    ("movement-pose-unknown", "movement uses an unknown pose", {"c.toml": BODY.replace('{ pose = "bob", at = 0.5 }', '{ pose = "bop", at = 0.5 }')}, ["validate", "c.toml"], ["key motor.movements.bob.keys[1].pose", "unknown pose 'bop'", "available: stand, bob"]),
    ("movement-not-hub", "movement does not end in a hub", {"c.toml": BODY.replace('{ pose = "stand", at = 1.0 }', '{ pose = "bob", at = 1.0 }')}, ["validate", "c.toml"], ["key motor.movements.bob.keys", "movement must end in a hub pose, not 'bob'", "available: stand"]),
    ("movement-times", "key times not increasing", {"c.toml": BODY.replace("at = 1.0", "at = 0.4")}, ["validate", "c.toml"], ["key motor.movements.bob.keys", "key times [0.0, 0.5, 0.4] are not increasing"]),
    ("movement-key-form", "a key is not { pose, at }", {"c.toml": BODY.replace('{ pose = "bob", at = 0.5 }', '{ pose = "bob" }')}, ["validate", "c.toml"], ["key motor.movements.bob.keys[1]", 'expected { pose = "NAME", at = SECONDS }']),
    ("rest-unknown", "rest pose unknown", {"c.toml": BODY.replace('plugin = "keyframe"', 'plugin = "keyframe"\nrest = "sit"')}, ["validate", "c.toml"], ["key motor.rest", "unknown hub pose 'sit'", "available: stand, bob"]),
    ("finger-unknown", "a hand names a finger the body does not have", {"c.toml": '[character]\nname = "X"\nextends = "moritz"\n[body.hands.left_hand]\nwrist = "left_wrist"\nfingers = ["left_thumb", "left_pinky"]\n'}, ["validate", "c.toml"], ["key body.hands.left_hand.fingers", "unknown body part 'left_pinky'", "available:", "left_little"]),
    ("finger-angles", "a finger given as two numbers", {"c.toml": '[character]\nname = "X"\nextends = "moritz"\n[motor.poses.left_fist]\nleft_index = [85.0, 95.0]\n'}, ["validate", "c.toml"], ["key motor.poses.left_fist.left_index", "expected [base, middle, spread] finger joint angles in degrees"]),
    ("script-movement", "script names an unknown movement", {"c.toml": BODY + '[action]\nplugin = "script"\nmovements = ["bob", "jump"]\n'}, ["validate", "c.toml"], ["key action.movements[1]", "unknown movement 'jump'", "available: bob"]),
    # -- the action hierarchy
    ("trigger-unknown", "unknown trigger", {"c.toml": CHILD + '[action.tuples.get]\ncan = [{ trigger = "proximty" }]\n'}, ["validate", "c.toml"], ["key action.tuples.get.can[0].trigger", "unknown trigger 'proximty'", "available: drive, holding"]),
    ("trigger-param", "trigger parameter unknown", {"c.toml": CHILD + '[action.tuples.get]\nuntil = [{ trigger = "holding", tight = true }]\n'}, ["validate", "c.toml"], ["key action.tuples.get.until[0].tight", "unknown parameter 'tight' for trigger 'holding'"]),
    ("tuple-child-unknown", "unknown child tuple", {"c.toml": CHILD + '[action.tuples.get]\nchildren = ["reach", "grab"]\n'}, ["validate", "c.toml"], ["key action.tuples.get.children[1]", "unknown tuple 'grab'", "available: eat, get"]),
    ("tuple-cycle", "cycle in the action hierarchy", {"c.toml": CHILD + '[action.tuples.get]\nchildren = ["reach", "loop"]\n[action.tuples.loop]\nchildren = ["get"]\n'}, ["validate", "c.toml"], ["action hierarchy cycle:"]),
    ("tuple-leaf-and-inner", "tuple with movement and children", {"c.toml": CHILD + '[action.tuples.reach]\nchildren = ["get"]\n'}, ["validate", "c.toml"], ["key action.tuples.reach", "a tuple needs either a movement"]),
    ("tuple-movement-unknown", "leaf requests an unknown movement", {"c.toml": CHILD + '[action.tuples.eat]\nmovement = "munch"\n'}, ["validate", "c.toml"], ["key action.tuples.eat.movement", "unknown movement 'munch'"]),
    ("top-without-drive", "top-level tuple without a drive", {"c.toml": CHILD + '[action.tuples.idle]\nmovement = "stand"\n'}, ["validate", "c.toml"], ["key action.tuples.idle.drive", "a top-level tuple is a motivational subsystem"]),
    ("drive-unknown", "tuple names an unknown drive", {"c.toml": CHILD + '[action.tuples.satisfy_hunger]\ndrive = "thirst"\n'}, ["validate", "c.toml"], ["key action.tuples.satisfy_hunger.drive", "unknown drive 'thirst'", "available: hunger, play"]),
    ("effect-unknown", "unknown effect", {"c.toml": CHILD + '[action.tuples.reach]\neffect = "throw"\n'}, ["validate", "c.toml"], ["key action.tuples.reach.effect", "unknown effect 'throw'", "available: none, grasp, consume, toss"]),
    ("drive-level", "drive level out of range", {"c.toml": CHILD + '[action.drives]\nhunger = { level = 2.0 }\n'}, ["validate", "c.toml"], ["key action.drives.hunger.level", "invalid value 2.0"]),
    ("experience-path", "experience names no path of the hierarchy", {"c.toml": CHILD + '[action.experience]\nreach = { "play > reach" = 1 }\n'}, ["validate", "c.toml"], ["key action.experience.reach", "not a path of the hierarchy: 'play > reach'"]),
    # -- scenario files
    ("scenario-missing-table", "scenario without [scenario]", {"s.toml": "[[scenario]]\nname = 1\n"}, ["validate", "s.toml"], ["key scenario", "missing [scenario] table"]),
    ("scenario-actor-key", "unknown actor key", {"s.toml": SCENE + "speed = 2\n"}, ["validate", "s.toml"], ["key actors[0].speed", "unknown key 'speed'", "available: id, character, position"]),
    ("scenario-watch", "watching an actor that does not exist", {"s.toml": SCENE + 'watch = "ghost"\n'}, ["validate", "s.toml"], ["key actors[0].watch", "unknown actor 'ghost'", "available:"]),
    ("scenario-duplicate-id", "two actors with one id", {"s.toml": SCENE + SCENE[SCENE.index("[[actors]]"):]}, ["validate", "s.toml"], ["key actors[1].id", "duplicate actor id 'max'", "available: max"]),
    ("scenario-position", "position is not [x, y, z]", {"s.toml": SCENE + "position = [0, 1]\n"}, ["validate", "s.toml"], ["key actors[0].position", "expected [x, y, z] in metres"]),
    ("scenario-character", "character not found", {"s.toml": SCENE.replace(MAX, "nobody")}, ["validate", "s.toml"], ["key actors[0].character", "cannot find 'nobody'", "available:"]),
    ("scenario-fps", "negative frame rate", {"s.toml": SCENE.replace('name = "s"', 'name = "s"\nfps = -30')}, ["validate", "s.toml"], ["key scenario.fps", "expected a positive number"]),
    ("scenario-holder", "object held by an unknown actor", {"s.toml": SCENE + '[[objects]]\nname = "cheese"\nkind = "cheese"\nheld_by = "morris"\n'}, ["validate", "s.toml"], ["key objects[0].held_by", "unknown actor 'morris'", "available: max"]),
    ("scenario-object-kind", "object without a kind", {"s.toml": SCENE + '[[objects]]\nname = "cheese"\n'}, ["validate", "s.toml"], ["key objects[0].kind", "missing or invalid"]),
    # -- motion capture: BVH files and body profiles
    ("bvh-token", "BVH hierarchy with a wrong word", {"m.bvh": BVH.replace("OFFSET 0 10 0", "OFSET 0 10 0")}, ["validate", "m.bvh"], ["m.bvh:8:5", "found 'OFSET'", "expected 'OFFSET'"]),
    ("bvh-channel", "unknown BVH channel", {"m.bvh": BVH.replace("Zrotation Xrotation Yrotation\n    End", "Zrotation Wrotation Yrotation\n    End")}, ["validate", "m.bvh"], ["m.bvh:9:", "found 'Wrotation'", "expected a channel name (Xposition"]),
    ("bvh-frame-values", "a frame with too few values", {"m.bvh": BVH.replace("0 91 0 0 0 0 0 0 0", "0 91 0 0 0 0 0 0")}, ["validate", "m.bvh"], ["m.bvh:20:1", "frame 2 has 8 values", "expected 9 channel values per frame line"]),
    ("bvh-frame-value", "a frame value that is not a number", {"m.bvh": BVH.replace("0 91 0 0", "0 nine 0 0")}, ["validate", "m.bvh"], ["m.bvh:20:3", "found 'nine'", "expected a number (a channel value)"]),
    ("bvh-frame-time", "zero frame time", {"m.bvh": BVH.replace("Frame Time: 0.0333333", "Frame Time: 0")}, ["validate", "m.bvh"], ["m.bvh:18:13", "frame time 0.0", "expected a positive number of seconds"]),
    ("bvh-frame-count", "fewer frame lines than announced", {"m.bvh": BVH.replace("Frames: 2", "Frames: 3")}, ["validate", "m.bvh"], ["m.bvh:", "2 frame lines after 'Frames: 3'", "expected 3 frame lines"]),
    ("bvh-missing", "BVH file that does not exist", {}, ["validate", "gone.bvh"], ["gone.bvh", "cannot read", "expected a readable BVH file"]),
    ("profile-table", "unknown table in a profile", {"p.toml": PROFILE + "[joints]\nx = 1\n"}, ["validate", "p.toml"], ["p.toml:11: key joints", "unknown table 'joints'", "available: profile, parts, facing, bones, colours"]),
    ("profile-units", "unknown units", {"p.toml": PROFILE.replace('"cm"', '"furlong"')}, ["validate", "p.toml"], ["key profile.units", "unknown units 'furlong'", "available: metre, meter, m, centimetre"]),
    ("profile-up", "unknown up axis", {"p.toml": PROFILE.replace('units = "cm"', 'units = "cm"\nup = "north"')}, ["validate", "p.toml"], ["key profile.up", "unknown up axis 'north'", "available: +y, -y, +z, -z, +x, -x"]),
    ("profile-no-root", "profile without a root part", {"p.toml": PROFILE.replace('root = "hips"', 'pelvis = "hips"')}, ["validate", "p.toml"], ["key parts", "no part named 'root'", "available: pelvis, head, nose"]),
    ("profile-facing", "facing names an unknown part", {"p.toml": PROFILE.replace('right = "nose"', 'right = "chin"')}, ["validate", "p.toml"], ["key facing.right", "unknown body part 'chin'", "available: root, head, nose"]),
    ("profile-joint", "a mapped joint the BVH file lacks", {"p.toml": PROFILE.replace('"head_end"', '"Nose"'), "m.bvh": BVH}, ["validate", "--body", "p.toml", "m.bvh"], ["key parts.nose", "joint 'Nose' of part 'nose' is not in", "available: hips, head, head_end"]),
    ("observe-matcher", "observe with an unknown matcher", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--matcher", "dtwx", "m.bvh"], ["unknown matcher 'dtwx'", "available: dtw, forward-model, path-search"]),
    # -- state files
    ("state-version", "state file of an unknown version", {"st.json": state(version=9)}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["st.json: key version", "unsupported state format version 9", "available: 1"]),
    ("state-not-json", "state file that is not JSON", {"st.json": "{\n oops\n"}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["st.json:2:", "not JSON"]),
    ("state-format", "a JSON file that is not a state file", {"st.json": '{"hello": 1}'}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["key format", "not a likeme state file"]),
    # -- the command line
    ("cli-command", "unknown command", {}, ["frobnicate"], ["invalid choice: 'frobnicate'"]),
    ("cli-missing-argument", "missing argument", {}, ["run"], ["the following arguments are required: scenario"]),
    ("cli-bad-int", "not a number", {}, ["demo", "--seed", "x"], ["argument --seed: invalid int value: 'x'"]),
    ("cli-bench-set", "bad --set", {}, ["bench", "watch", "--movements", "1", "--set", "floor=0"], ["key --set", "invalid setting 'floor=0'", "expected TABLE.KEY=VALUE"]),
    # -- views
    ("view-width-huge", "a picture 100,000 pixels wide", {}, ["show", "max", "--view", "body", "--set", "width=100000"], ["key width", "value 100000 out of range", "expected an integer in [64, 8192]"]),
    ("view-unknown", "unknown view", {}, ["show", "max", "--view", "graph"], ["unknown view 'graph'", "available:", "hub-signal"]),
    ("view-segmenter", "a signal view of a segmenter the character does not have", {}, ["show", "max", "--view", "speed-profile"], ["key --view", "Max has no velocity-direction segmenter (its segmenter is 'hub-threshold')", "expected a character whose [segmenter] plugin is velocity-direction"]),
    ("view-movement", "a view asked to perform an unknown movement", {}, ["show", "max", "--view", "hub-signal", "--set", 'movements=["fly"]'], ["key movements", "unknown movement 'fly'", "available:", "wave"]),
    # -- config: every file, parameter and argument bounded and checked where it enters (issue 21)
    ("param-nan", "a NaN parameter", {"c.toml": CHILD + "[perception]\nnoise = nan\n"}, ["validate", "c.toml"], ["c.toml:5: key perception.noise", "value nan is not a finite number"]),
    ("param-inf-nested", "an infinite number inside a table parameter", {"c.toml": CHILD + "[motor.poses.stand]\nhead = [0, inf, 0]\n"}, ["validate", "c.toml"], ["key motor.poses.stand.head[1]", "value inf is not a finite number", "expected finite numbers"]),
    ("toml-deep", "TOML nested 10,000 deep", {"c.toml": "x = " + "[" * 10000 + "]" * 10000 + "\n"}, ["validate", "c.toml"], ["c.toml", "TOML nested more than 32 levels deep"]),
    ("toml-deep-tables", "inline tables nested 10,000 deep", {"c.toml": "x = " + "{a=" * 10000 + "1" + "}" * 10000 + "\n"}, ["validate", "c.toml"], ["c.toml", "TOML nested more than 32 levels deep"]),
    ("extends-chain", "an extends chain of 1,200 files", {f"c{i}.toml": f'[character]\nname = "C{i}"\nextends = "c{i + 1}.toml"\n' for i in range(1200)}, ["validate", "c0.toml"], ["c63.toml", "key character.extends", "extends chain longer than 64 files"]),
    ("facing-same-part", "facing left and right the same part", {"c.toml": BODY.replace('right = "rk"', 'right = "lk"')}, ["validate", "c.toml"], ["key body.facing.right", "left and right are the same part 'lk'", "available: root, head, rk"]),
    ("bone-to-itself", "a bone from a part to itself", {"c.toml": BODY.replace("facing =", 'bones = [["root", "head"], ["head", "head"]]\nfacing =')}, ["validate", "c.toml"], ["key body.bones[1]", "a bone from part 'head' to itself"]),
    ("profile-units-inf", "infinite units in a profile", {"p.toml": PROFILE.replace('"cm"', "inf")}, ["validate", "p.toml"], ["p.toml:3: key profile.units", "invalid units inf"]),
    ("profile-up-list", "up given as a list", {"p.toml": PROFILE.replace('units = "cm"', 'units = "cm"\nup = ["+y"]')}, ["validate", "p.toml"], ["key profile.up", "wrong type list", 'expected one axis as a string, like up = "+z"']),
    ("profile-facing-same", "a profile facing left and right the same part", {"p.toml": PROFILE.replace('right = "nose"', 'right = "head"')}, ["validate", "p.toml"], ["p.toml:10: key facing.right", "left and right are the same part 'head'"]),
    ("profile-bone-self", "a profile bone from a part to itself", {"p.toml": 'bones = [["head", "head"]]\n' + PROFILE}, ["validate", "p.toml"], ["p.toml:1: key bones[0]", "a bone from part 'head' to itself"]),
    ("scenario-properties", "object properties not a table", {"s.toml": SCENE + '[[objects]]\nname = "c"\nkind = "food"\nproperties = "abc"\n'}, ["validate", "s.toml"], ["key objects[0].properties", "wrong type str", "expected a table of properties"]),
    ("scenario-held-by-list", "held_by given as a list", {"s.toml": SCENE + '[[objects]]\nname = "c"\nkind = "food"\nheld_by = ["max"]\n'}, ["validate", "s.toml"], ["key objects[0].held_by", "wrong type list", "expected the id of one actor, as a string", "available: max"]),
    ("scenario-colour", "an object colour that is not #rrggbb", {"s.toml": SCENE + '[[objects]]\nname = "c"\nkind = "food"\ncolour = "purplish"\n'}, ["run", "s.toml", "--render", "out"], ["key objects[0].colour", "invalid colour 'purplish'", 'expected a colour "#rrggbb"']),
    ("scenario-tail", "a tail of 1e300 seconds", {"s.toml": SCENE.replace('name = "s"', 'name = "s"\ntail = 1e300')}, ["validate", "s.toml"], ["key scenario.tail", "invalid value 1e+300", "expected seconds in [0, 3600]"]),
    ("scenario-fps-high", "a frame rate of a million", {"s.toml": SCENE.replace('name = "s"', 'name = "s"\nfps = 1e6')}, ["validate", "s.toml"], ["key scenario.fps", "invalid value 1000000.0", "at most 1000"]),
    ("scenario-frames", "a run of more frames than bounded", {"s.toml": SCENE.replace('name = "s"', 'name = "s"\nfps = 1000\nduration = 3600')}, ["validate", "s.toml"], ["key scenario.duration", "duration 3600 s at 1000 fps is 3600000 frames", "expected at most 432000 frames"]),
    ("scenario-seed", "a negative seed in a scenario", {"s.toml": SCENE.replace('name = "s"', 'name = "s"\nseed = -1')}, ["validate", "s.toml"], ["key scenario.seed", "invalid seed -1", "expected an integer in [0, "]),
    ("script-random", "a script drawing 100,000,000 movements", {"s.toml": SCENE + '[actors.override.action]\nplugin = "script"\nrandom = 100000000\n'}, ["validate", "s.toml"], ["s.toml:8: key actors[0].override.action.random", "value 100000000 out of range", "expected an integer in [0, 100000]"]),
    ("override-typo", "a scenario override's typo (reported in the scenario)", {"s.toml": SCENE + '[actors.override.segmenter]\ntreshold = 0.1\n'}, ["validate", "s.toml"], ["s.toml:7: key actors[0].override.segmenter.treshold", "unknown parameter 'treshold' for segmenter 'hub-threshold'"]),
    ("cli-duration-nan", "--duration nan", {}, ["run", "demo", "--duration", "nan"], ["argument --duration: invalid value 'nan'", "expected seconds in [0, 3600]"]),
    ("cli-duration-inf", "--duration inf", {}, ["run", "demo", "--duration", "inf"], ["argument --duration: invalid value 'inf'"]),
    ("cli-seed-negative", "--seed -1", {}, ["run", "demo", "--seed", "-1"], ["argument --seed: invalid seed -1", "expected an integer in [0, 9223372036854775807]"]),
    ("cli-json-folder", "--json into a folder that does not exist", {}, ["bench", "watch", "--movements", "1", "--json", "/nonexistent/x.json"], ["/nonexistent: key --json", "no such folder", "expected a file in an existing folder"]),
    ("cli-render-file", "--render to a file, not a folder", {"f.txt": "x\n"}, ["run", "demo", "--render", "f.txt"], ["f.txt: key --render", "not a folder"]),
    ("cli-render-unwritable", "--render below a file", {"f.txt": "x\n"}, ["run", "demo", "--render", "f.txt/frames"], ["f.txt/frames: key --render", "cannot create the folder"]),
    ("bench-data-file", "bench make-data into a file", {"f.txt": "x\n"}, ["bench", "make-data", "f.txt"], ["f.txt: key DIR", "not a folder"]),
    ("bench-dropout", "bench watch --dropout 2", {}, ["bench", "watch", "--dropout", "2"], ["argument --dropout: invalid value '2'", "expected a probability in [0, 1]"]),
    ("observe-set-typo", "observe --set with a misspelt key", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--set", "matcher.kk=3", "m.bvh"], ["key --set.matcher.kk", "unknown parameter 'kk'", "available:"]),
    ("observe-set-table-typo", "observe --set with a misspelt key of a parameter's own table", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--correspondence", "body-mapping", "--set", "correspondence.dwell.sped=0.1", "m.bvh"], ["key --set.correspondence.dwell.sped", "unknown parameter 'sped' in table 'dwell' of correspondence 'body-mapping'", "available: memory, speed, window"]),
    ("set-table-typo", "--set with a misspelt table", {}, ["bench", "watch", "--movements", "1", "--set", "matchr.k=3"], ["key --set.matchr", "unknown table 'matchr'", "available: motor, perception, correspondence, segmenter, matcher, action"]),
    ("set-key-unknown", "--set with a key of no named matcher", {"p.toml": PROFILE}, ["bench", "recognition", "--body", "p.toml", "--repertoire", ".", "--matcher", "path-search", "--matcher", "dtw", "--set", "matcher.search=per-movement"], ["key --set.matcher.search", "unknown parameter 'search' for matcher 'dtw'", "available: calibrated, decision, distance, features, parts, stride, window"]),
    ("scenario-radius", "an object of negative radius", {"s.toml": SCENE + '[[objects]]\nname = "c"\nkind = "food"\nradius = -1\n'}, ["validate", "s.toml"], ["key objects[0].radius", "invalid value -1", "expected a positive number of metres"]),
    ("bench-lengths-nan", "bench --lengths-for-height nan", {"p.toml": PROFILE}, ["bench", "recognition", "--body", "p.toml", "--repertoire", ".", "--lengths-for-height", "nan"], ["argument --lengths-for-height: invalid value 'nan'", "expected metres in [0, 1000]"]),
    ("profile-units-huge", "units an integer too large for a float", {"p.toml": PROFILE.replace('"cm"', "9" * 400)}, ["validate", "p.toml"], ["key profile.units", "invalid units", "expected a unit name or a positive number"]),
    ("param-int-huge", "an integer parameter beyond 64 bits", {"c.toml": CHILD + "[matcher.beam]\nk = " + "9" * 30 + "\n"}, ["validate", "c.toml"], ["key matcher.beam.k", "integer too large"]),
    ("param-float-huge", "a float parameter given as a 400-digit integer", {"c.toml": CHILD + "[perception]\nnoise = " + "9" * 400 + "\n"}, ["validate", "c.toml"], ["key perception.noise", "number too large"]),
    ("character-name-long", "a character reference of 5,000 characters", {"s.toml": SCENE.replace(MAX, "x" * 5000)}, ["validate", "s.toml"], ["key actors[0].character", "(5000 characters)", "available:"]),
    ("set-value-nan", "--set with a NaN value", {}, ["bench", "watch", "--movements", "1", "--set", "perception.noise=nan"], ["key --set.perception.noise", "value nan is not a finite number for perception 'synthetic-vision'"]),
    # -- watching: bounded working memory and the memory benchmark
    ("bench-memory-minutes", "memory benchmark for nan minutes", {}, ["bench", "memory", "--minutes", "nan"], ["argument --minutes: invalid value 'nan'", "expected minutes in [0.001, 1440]"]),
    ("bench-memory-block", "memory benchmark with packets of 0 frames", {}, ["bench", "memory", "--block", "0"], ["argument --block: invalid value 0", "expected an integer in [1, 100000]"]),
    ("observe-ruptures-window", "ruptures with a negative window", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "ruptures", "--set", "segmenter.window=-1", "m.bvh"], ["key --set.segmenter.window", "value -1.0 out of range", "expected a number in [0, 3600]"]),
    ("observe-max-movement", "velocity-direction with a negative max_movement", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "velocity-direction", "--set", "segmenter.max_movement=-5", "m.bvh"], ["key --set.segmenter.max_movement", "value -5.0 out of range"]),
    # -- reading: bounded, streaming BVH and profile reading (issue 21)
    ("bvh-frame-rate", "a frame time of 0.1 microseconds (10 MHz)", {"m.bvh": BVH.replace("Frame Time: 0.0333333", "Frame Time: 1e-7")}, ["validate", "m.bvh"], ["m.bvh:18:13", "frame time 1e-07 s (1e+07 frames per second)", "expected a frame time of 0.0001 to 60 seconds"]),
    ("bvh-nesting", "joints nested 1,000 deep", {"m.bvh": DEEP_BVH}, ["validate", "m.bvh"], ["m.bvh:1026:1", "joints nested deeper than 256", "expected at most 256 levels of JOINT"]),
    ("bvh-no-channels", "no channels in the whole file", {"m.bvh": BVH.replace("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", "CHANNELS 0").replace("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 0")}, ["validate", "m.bvh"], ["m.bvh:16:1", "no channels in the hierarchy", "expected at least one joint with CHANNELS"]),
    ("bvh-channel-digit", "a channel count in superscript digits", {"m.bvh": BVH.replace("CHANNELS 3", "CHANNELS \u00b2")}, ["validate", "m.bvh"], ["m.bvh:9:14", "found '\u00b2'", "expected the number of channels (ASCII digits, at most 6)"]),
    ("bvh-frames-huge", "Frames: 10**12 with two frame lines", {"m.bvh": BVH.replace("Frames: 2", "Frames: 1000000000000")}, ["validate", "m.bvh"], ["m.bvh:21:1", "2 frame lines after 'Frames: 1000000000000'", "expected 1000000000000 frame lines"]),
    ("bvh-dev-zero", "a device given as a clip", {"p.toml": PROFILE}, ["observe", "--body", "p.toml", "--repertoire", ".", "/dev/zero"], ["/dev/zero: is a character device, not a file", "expected a regular file (BVH file)"]),
    ("bvh-directory", "a directory given as a clip", {"p.toml": PROFILE}, ["observe", "--body", "p.toml", "--repertoire", ".", "."], [".: is a directory, not a file", "expected a regular file (BVH file)"]),
    ("profile-dev-zero", "a device given as a body profile", {"m.bvh": BVH}, ["observe", "--body", "/dev/zero", "--repertoire", ".", "m.bvh"], ["/dev/zero: is a character device, not a file", "expected a regular file (body profile)"]),
    ("validate-dev-zero", "a device given to validate", {}, ["validate", "/dev/zero"], ["/dev/zero: is a character device, not a file", "expected a regular file (TOML file)"]),
    ("validate-directory", "a directory given to validate", {}, ["validate", "."], [".: is a directory, not a file", "expected a regular file (TOML file)"]),
    # -- state files: saving and loading (issue 21)
    ("state-save-folder", "--save into a folder that does not exist", {}, ["run", "demo", "--save", "missing/st.json"], ["missing/st.json: the folder missing does not exist", "expected --save into an existing folder"]),
    ("state-save-parent-file", "--save below a file", {"f.txt": "x"}, ["run", "demo", "--save", "f.txt/st.json"], ["f.txt/st.json: f.txt is a file, not a folder"]),
    ("state-save-directory", "--save to a folder", {}, ["run", "demo", "--save", "/usr"], ["/usr: is a folder, not a file"]),
    ("state-save-not-state", "--save over a file that is not a state file", {"notes.txt": "my notes"}, ["run", "demo", "--save", "notes.txt"], ["notes.txt: exists and is not a likeme state file; refusing to overwrite it"]),
    ("state-checksum", "a state file changed after likeme wrote it", {"st.json": state(version=2, checksum="sha256:00")}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["st.json: key checksum: checksum does not match the content"]),
    ("state-no-checksum", "a version-2 state file without a checksum", {"st.json": state(version=2)}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["st.json: key checksum: missing checksum"]),
    ("state-character", "a state saved from another character", {"st.json": state(actors={"max": {"character": "Moritz", "components": {}}})}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["key actors.max.character: state saved from Moritz, but actor 'max' is Max", "available: max (Moritz)"]),
    ("state-learned-list", "learned movements as a list", {"st.json": state(actors={"max": {"character": "Max", "components": {"motor": {"plugin": "posegraph", "state": {"learned": []}}}}})}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["key actors.max.components.motor.state.learned: invalid learned movements"]),
    ("state-count", "a count that is not a number", {"st.json": state(actors={"max": {"character": "Max", "components": {"action": {"plugin": "hierarchical", "state": {"transitions": [["reach", "eat", "abc"]]}}}}})}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["key actors.max.components.action.state.transitions[0][2]: invalid count 'abc'"]),
    ("state-list-name", "a list where a name belongs", {"st.json": state(actors={"max": {"character": "Max", "components": {"action": {"plugin": "hierarchical", "state": {"transitions": [[["reach"], "eat", 1]]}}}}})}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["invalid transition [['reach'], 'eat', 1]"]),
    ("state-not-table", "a component's state that is not a table", {"st.json": state(actors={"max": {"character": "Max", "components": {"action": {"plugin": "hierarchical", "state": 5}}}})}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["key actors.max.components.action.state: int instead of a table"]),
    ("state-deep", "nesting 40 deep", {"st.json": state(frame=[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[0]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]])}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["nested more than 32 deep"]),
    ("state-huge-int", "a huge integer", {"st.json": state(frame=10**40)}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["st.json: key frame: integer too large (41 digits)"]),
    ("state-load-device", "--load of a device", {}, ["run", "demo", "--load", "/dev/zero"], ["/dev/zero: is a character device, not a file; expected a regular file (state file written by --save)"]),
    ("state-nan", "NaN in a state file", {"st.json": state(time=float("nan"))}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["not JSON likeme reads: NaN is not a finite number"]),
    ("state-save-empty", "--save with an empty name", {}, ["run", "demo", "--duration", "0.1", "--save", ""], ["key --save: an empty file name", "expected --save FILE"]),
    ("state-load-empty", "--load with an empty name", {}, ["run", "demo", "--duration", "0.1", "--load", ""], ["key --load: an empty file name", "expected --load STATE"]),
    ("state-save-long-name", "--save with a 300-character name", {}, ["run", "demo", "--duration", "0.1", "--save", "s" * 300], ["a file name of 300 bytes is too long", "expected a name of at most"]),
    ("state-load-long-name", "--load with a 300-character name", {}, ["run", "demo", "--duration", "0.1", "--load", "s" * 300], ["cannot read file (File name too long)"]),
    ("state-surrogate", "a lone surrogate in a state file", {"st.json": state(actors={"max\ud800": {"character": "Max", "components": {}}})}, ["run", "demo", "--duration", "0.1", "--load", "st.json"], ["st.json: key actors: a key holding the lone surrogate \\ud800", "expected strings of Unicode characters"]),
    # -- profiling: profiles that check themselves (issue 20)
    ("bvh-end-site-name", "a joint named like an end site", {"m.bvh": BVH.replace("  }\n}\nMOTION", "  }\n  JOINT head_end\n  {\n    OFFSET 0 1 0\n    CHANNELS 0\n  }\n}\nMOTION")}, ["validate", "m.bvh"], ["m.bvh:15:9", "duplicate joint name 'head_end', the name of the end site of joint 'head' at line 10", "expected unique joint names"]),
    ("profile-npy", "likeme profile of a .npy array", {"a.npy": "x"}, ["profile", "a.npy"], ["a.npy: key FILE", "cannot propose a profile for a .npy file", "expected a BVH file, a CSV of joint positions or a C3D file (a .npy array has no joint names)"]),
    ("profile-missing", "likeme profile of a missing file", {}, ["profile", "take.bvh"], ["take.bvh: cannot read (No such file or directory)", "expected a readable recording"]),
    ("profile-out-folder", "likeme profile --out into a missing folder", {"m.bvh": BVH}, ["profile", "m.bvh", "--out", "no/p.toml"], ["no: key --out", "no such folder"]),
    ("profile-csv-header", "likeme profile of a CSV without joint columns", {"k.csv": "time,a,b\n0,1,2\n"}, ["profile", "k.csv"], ["k.csv:1: no joint columns in the header", "available: time, a, b"]),
    # -- views of your own recordings (likeme show --body PROFILE FILE ... --view NAME)
    ("show-recording-no-view", "recordings to show without a view", {"p.toml": PROFILE, "m.bvh": BVH}, ["show", "--body", "p.toml", "m.bvh"], ["key --view", "recordings without --view", "available:", "hub-signal"]),
    ("show-recording-view", "recordings shown by a view that draws none", {"p.toml": PROFILE, "m.bvh": BVH}, ["show", "--body", "p.toml", "m.bvh", "--view", "posegraph"], ["key --view", "view 'posegraph' does not draw recordings", "available:", "speed-profile"]),
    ("show-recording-no-body", "a recording shown without its body profile", {"m.bvh": BVH}, ["show", "m.bvh", "--view", "body"], ["key character", "cannot show m.bvh", "with --body PROFILE recordings"]),
    ("show-recordings-one-png", "two recordings' pictures to one file", {"p.toml": PROFILE, "m.bvh": BVH}, ["show", "--body", "p.toml", "m.bvh", "m.bvh", "--view", "hub-signal", "--out", "x.png"], ["x.png: key --out", "one file for several pictures", "expected a folder"]),
    # -- wiring: joint-position recordings through profiles, --fps, live input (issue 20)
    ("observe-unknown-format", "a recording of an unknown format", {"p.toml": PROFILE, "m.txt": "x"}, ["observe", "--body", "p.toml", "--repertoire", ".", "m.txt"], ["m.txt: unknown recording format '.txt'", "available: .bvh, .csv, .npy"]),
    ("observe-missing-c3d", "a C3D file named that is not there", {"p.toml": PROFILE}, ["observe", "--body", "p.toml", "--repertoire", ".", "gone.c3d"], ["gone.c3d: cannot read", "expected a readable recording of joint positions"]),
    ("observe-stdin-and-files", "standard input mixed with files", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "-", "m.bvh"], ["key files: '-' (standard input) with 1 other file(s)", "expected either '-' alone"]),
    ("csv-no-frame-rate", "a CSV without a time column, no --fps, no fps in the profile", {"p.toml": PROFILE, "m.csv": "hips_x,hips_y,hips_z\n0,1,2\n"}, ["validate", "--body", "p.toml", "m.csv"], ["m.csv: no frame rate: the file has no 'time' column", "--fps"]),
    ("csv-missing-joint", "a CSV without a joint the profile maps", {"p.toml": PROFILE, "m.csv": "hips_x,hips_y,hips_z,head_x,head_y,head_z\n0,1,2,0,2,0\n"}, ["validate", "--fps", "30", "--body", "p.toml", "m.csv"], ["p.toml:7: key parts.nose", "joint 'head_end' of part 'nose' is not in m.csv", "available: hips, head"]),
    ("npy-not-an-array", "a .npy file that is text", {"m.npy": "x"}, ["validate", "--fps", "30", "m.npy"], ["m.npy: not a .npy file (no NumPy header)", "expected a NumPy array (frames, joints, 3) of numbers"]),
    ("fps-option", "--fps of 0", {"m.bvh": BVH}, ["validate", "--fps", "0", "m.bvh"], ["argument --fps: invalid frame rate '0'", "expected frames per second in [1/60, 10000]"]),
    ("fps-option-tiny", "--fps of 1e-300", {"m.bvh": BVH}, ["validate", "--fps", "1e-300", "m.bvh"], ["argument --fps: invalid frame rate '1e-300'", "expected frames per second in [1/60, 10000]"]),
    ("param-seconds-overflow", "a segmenter's floor of 1e308 seconds", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--set", "segmenter.floor=1e308", "m.bvh"], ["key --set.segmenter.floor: value 1e+308 out of range for segmenter 'hub-threshold'", "expected a number in [0, 3600]"]),
    ("param-max-gap-overflow", "a segmenter's max_gap of 1e308 seconds", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--set", "segmenter.max_gap=1e308", "m.bvh"], ["key --set.segmenter.max_gap: value 1e+308 out of range", "expected a number in [0, 3600]"]),
    ("param-memory-overflow", "velocity-direction's sensory memory of 1e308 seconds", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "velocity-direction", "--set", "segmenter.memory=1e308", "m.bvh"], ["key --set.segmenter.memory: value 1e+308 out of range", "expected a number in [0, 3600]"]),
    ("param-max-movement-overflow", "velocity-direction's max_movement of 1e308 seconds", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "velocity-direction", "--set", "segmenter.max_movement=1e308", "m.bvh"], ["key --set.segmenter.max_movement: value 1e+308 out of range", "expected a number in [0, 3600]"]),
    ("param-window-overflow", "ruptures' window of 1e308 seconds", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "ruptures", "--set", "segmenter.window=1e308", "m.bvh"], ["key --set.segmenter.window: value 1e+308 out of range", "expected a number in [0, 3600]"]),
    ("param-huge-number", "a number parameter of 1e308 in a character file", {"c.toml": CHILD + "[perception]\nrange = 1e308\n"}, ["validate", "c.toml"], ["c.toml:5: key perception.range: value 1e+308 too large", "expected a number in [0, 1e+09]"]),
    ("param-huge-duration", "a duration parameter of 1e308 seconds in a character file", {"c.toml": CHILD + "[perception]\nbuffer = 1e308\n"}, ["validate", "c.toml"], ["c.toml:5: key perception.buffer: value 1e+308 out of range", "expected a number in [0, 3600]"]),
    ("bench-vision-frames-zero", "bench vision --frames 0", {}, ["bench", "vision", "--frames", "0"], ["argument --frames: invalid value 0", "expected an integer in [1, 10000]"]),
    ("bench-facilitation-noise-nan", "bench facilitation --noise nan", {}, ["bench", "facilitation", "--noise", "nan"], ["argument --noise: invalid value 'nan'", "expected metres in [0, 1]"]),
    ("bench-facilitation-repertoire", "bench facilitation --repertoire -3", {}, ["bench", "facilitation", "--repertoire", "-3"], ["argument --repertoire: invalid value -3", "expected an integer in [1, 100]"]),
    ("bench-facilitation-hands", "bench facilitation --hands 5", {}, ["bench", "facilitation", "--hands", "5"], ["argument --hands: invalid value '5'", "expected a share of the demonstrations in [0, 1]"]),
    ("bench-behaviour-episodes", "bench behaviour --episodes -1", {}, ["bench", "behaviour", "--episodes", "-1"], ["argument --episodes: invalid value -1", "expected an integer in [1, 100000]"]),
    ("bench-scaling-minutes", "bench scaling --minutes 1e6", {}, ["bench", "scaling", "--minutes", "1e6"], ["argument --minutes: invalid value '1e6'", "expected minutes in [0.001, 600]"]),
    ("bench-scaling-frames", "bench scaling with a stream of too many frames", {}, ["bench", "scaling", "--minutes", "600", "--fps", "120"], ["key --minutes: 600 minutes at 120 fps are 4,320,000 frames", "expected at most 1,000,000 frames a stream"]),
    ("bench-posegraph-nodes", "bench posegraph --nodes 10000000", {}, ["bench", "posegraph", "--nodes", "10000000"], ["argument --nodes: invalid value 10000000", "expected an integer in [1, 500000]"]),
    ("bench-bandai-few-clips", "bench bandai with too few clips", {"dataset-1_bow_normal_001.bvh": BVH, "dataset-1_bow_angry_001.bvh": BVH}, ["bench", "bandai", ".", "out"], [": 1 demos of the repertoire's movements in other styles than normal", "expected at least 5", "available: dataset-1_bow_angry_001.bvh"]),
    ("bench-fuzz-timeout", "bench fuzz --timeout inf", {}, ["bench", "fuzz", "--timeout", "inf"], ["argument --timeout: invalid value 'inf'", "expected seconds in [0.1, 3600]"]),
    ("csv-header-escapes", "a CSV header cell holding terminal escapes", {"e.csv": "time,\x1b]0;pwn\x07\x1b[2J_x,b_y\n0,1,2\n"}, ["validate", "e.csv"], ["e.csv:1: joint '\\x1b]0;pwn\\x07\\x1b[2J' has no y or z column"]),
    ("long-available-list", "an error whose list of names is 1,004 long", {"c.toml": BODY.replace('parts = ["root", "head", "lk", "rk"]', "parts = [" + ", ".join(f'"{n}"' for n in ["root", "head", "lk", "rk"] + [f"p{i}" for i in range(1000)]) + "]").replace('root = "root"', 'root = "pelvis"')}, ["validate", "c.toml"], ["key body.root: unknown body part 'pelvis'", "available: root, head, lk, rk, p0, p1", "p55 and 944 more"]),
    ("template-lengths-datetime", "an observer template's lengths_for_height a date", {"o.toml": '[observer]\nname = "o"\nlengths_for_height = 1979-05-27T07:32:00Z\n'}, ["validate", "o.toml"], ["o.toml:3: key observer.lengths_for_height: invalid value datetime.datetime(1979", "expected a positive number"]),
    ("toml-huge-integer", "an integer of 5,000 digits in a TOML value", {"c.toml": CHILD + "[segmenter]\nfloor = " + "9" * 5000 + "\n"}, ["validate", "c.toml"], ["c.toml:5:9: an integer of 5,000 digits", "expected an integer of at most 4300 digits"]),
    ("sweep-huge-integer", "an integer of 5,000 digits in a sweep grid", {"grid.toml": 'benchmark = "recognition"\nx = ' + "9" * 5000 + "\n"}, ["bench", "sweep", "grid.toml"], ["grid.toml:2:5: an integer of 5,000 digits", "expected an integer of at most 4300 digits"]),
    ("profile-fps", "a profile's fps is not a frame rate", {"p.toml": PROFILE.replace('units = "cm"', 'units = "cm"\nfps = -30')}, ["validate", "p.toml"], ["p.toml:4: key profile.fps: invalid fps -30", "expected frames per second"]),
    ("profile-joints", "a profile's joints list lacks a mapped joint", {"p.toml": PROFILE.replace('units = "cm"', 'units = "cm"\njoints = ["hips", "head"]')}, ["validate", "p.toml"], ["p.toml:4: key profile.joints: joint 'head_end' of part 'nose' is not in the joints list", "available: hips, head"]),
    # -- sweeps: likeme bench sweep, --jobs, --scheduler (issue 22)
    ("sweep-key", "a sweep grid with an unknown key", {"g.toml": 'benchmark = "stream"\nthreads = 4\n'}, ["bench", "sweep", "g.toml"], ["g.toml", "threads", "available:"]),
    ("sweep-folder", "a sweep grid naming a missing folder", {"g.toml": 'benchmark = "segmentation"\n[data.d]\nbody = "p.toml"\nstreams = "nowhere"\n', "p.toml": PROFILE}, ["bench", "sweep", "g.toml"], ["nowhere"]),
    ("sweep-scheduler", "--scheduler local: without a number", {"p.toml": PROFILE}, ["bench", "segmentation", "--body", "p.toml", "--streams", ".", "--scheduler", "local:x"], ["local:x"]),
    # -- acting: do-until persistence and retries, chance of a leaf's effect (issue 19)
    ("tuple-chance", "a leaf's chance outside [0, 1]", {"c.toml": CHILD + '[action.tuples.reach]\nchance = 1.5\n'}, ["validate", "c.toml"], ["key action.tuples.reach.chance", "invalid value 1.5", "probability in [0, 1]"]),
    ("tuple-chance-inner", "a chance on a tuple with children", {"c.toml": CHILD + '[action.tuples.get]\nchance = 0.5\n'}, ["validate", "c.toml"], ["key action.tuples.get.chance", "only a leaf"]),
    ("tuple-retries", "retries that are not a whole number", {"c.toml": CHILD + '[action.tuples.get]\nretries = 1.5\n'}, ["validate", "c.toml"], ["key action.tuples.get.retries", "invalid value 1.5", "whole number in [0, 100]"]),
    ("tuple-retries-leaf", "retries on a leaf", {"c.toml": CHILD + '[action.tuples.reach]\nretries = 2\n'}, ["validate", "c.toml"], ["key action.tuples.reach.retries", "only a tuple with children"]),
    # -- --jobs and --scheduler on every likeme bench sub-command (issue 22)
    ("bench-jobs-zero", "--jobs 0", {}, ["bench", "watch", "--jobs", "0"], ["argument --jobs: invalid value 0", "expected an integer in [1, 1024]"]),
    ("bench-scheduler-nonsense", "--scheduler that is no address", {}, ["bench", "posegraph", "--scheduler", "nonsense"], ["argument --scheduler: invalid address 'nonsense'", "tcp://HOST:PORT", "local:N"]),
    ("bench-scheduler-local-zero", "--scheduler local:0", {}, ["bench", "fuzz", "--scheduler", "local:0"], ["argument --scheduler: invalid value 'local:0'", "local:N with N workers, 1 or more"]),
    ("bench-runs-zero", "--runs 0", {}, ["bench", "facilitation", "--runs", "0"], ["argument --runs: invalid value 0", "expected an integer in [1, 10000]"]),
    ("bench-runs-past-seeds", "runs whose seeds pass the largest seed", {}, ["bench", "watch", "--seed", "9223372036854775807", "--runs", "2"], ["key --runs", "--seed + runs - 1 at most 9223372036854775807"]),
    ("bench-worker-error", "an error in a --jobs worker", {}, ["bench", "watch", "--runs", "2", "--jobs", "2", "--movements", "1", "--demonstrator", "nobody"], ["nobody"]),
    ("bench-vision-observer", "bench vision with an actor not in the scenario", {}, ["bench", "vision", "--observer", "nobody", "--frames", "1"], ["key --observer: no actor 'nobody' in 'jump_then_cover_face'", "available: max"]),
    # -- the look-at layer: [layer] (issue 19)
    ("layer-part", "a look-at turning a part the body lacks", {"c.toml": CHILD + '[layer]\nparts = ["tail"]\n'}, ["validate", "c.toml"], ["c.toml:5: key layer.parts[0]", "unknown part 'tail'", "available: root, head, nose"]),
    ("layer-yaw", "a look-at turning the head round to the back", {"c.toml": CHILD + '[layer]\nyaw = 95.0\n'}, ["validate", "c.toml"], ["c.toml:5: key layer.yaw", "value 95.0 out of range", "expected a number in [0, 89]"]),
    ("layer-plugin", "an unknown layer", {"c.toml": CHILD + '[layer]\nplugin = "look-around"\n'}, ["validate", "c.toml"], ["c.toml:5: key layer.plugin", "unknown layer 'look-around'", "available: look-at"]),
    # -- Fig. 3 and the speed re-parameterisation: an edge's demonstration in a state file (issue 19)
    ("state-edge-shown", "a learned edge whose demonstration has the wrong shape", {"st.json": state(actors={"max": {"character": "Max", "components": {"motor": {"plugin": "motor-command-graph", "state": {"left_wrist": {"nodes": {"n1": [[0.26, 1.4, 0.4]]}, "edges": [{"from": "hub", "to": "n1", "name": "left_wrist:e1", "commands": [{"start": [0.25, 0.92, 0.06], "target": [0.26, 1.4, 0.4], "duration": 0.9}], "shown": [[0.25, 0.92], [0.26, 1.4]], "shown_fps": 30.0}]}}}}}})}, ["run", "imitation_games", "--duration", "0.1", "--load", "st.json"], ["key actors.max.components.motor.state.left_wrist.edges[0].shown: invalid shown", "expected the demonstration's frames, at least two, each [x, y, z] of its 1 parts, finite"]),
    # -- path search across styles: posture, amplitude (issue 18, ps18)
    # -- path search's decision with the styled comparison: spread_quantile (issue 18, ps18b)
    # -- velocity-direction's end of a movement: end, rest.radius (issue 18, vd18)
    ("observe-vd-end", "velocity-direction's end misnamed", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "velocity-direction", "--set", "segmenter.end=home", "m.bvh"], ["key --set.segmenter.end", "value 'home' not allowed", "available: still, rest"]),
    ("observe-vd-rest-radius", "velocity-direction with a negative rest radius", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--segmenter", "velocity-direction", "--set", "segmenter.rest.radius=-1", "m.bvh"], ["key --set.segmenter.rest.radius", "value -1.0 out of range"]),
    # -- an observer template's tables for plugins named instead of its own: [segmenters.NAME] (issue 18)
    ("template-alternative-key", "an unknown parameter in a named plugin's own table", {"o.toml": '[observer]\nname = "o"\n[segmenters.velocity-direction]\nlevl = "movement"\n'}, ["validate", "o.toml"], ["o.toml:4: key segmenters.velocity-direction.levl", "unknown parameter 'levl' for segmenter 'velocity-direction'", "available: angle"]),
    ("template-alternative-plugin", "a table for a plugin that does not exist", {"o.toml": '[observer]\nname = "o"\n[matchers.nearest]\nk = 1\n'}, ["validate", "o.toml"], ["o.toml:3: key matchers.nearest", "unknown matcher 'nearest'", "available: dtw, forward-model, path-search"]),
    ("template-alternative-named", "a plugin named inside a plugin's own table", {"o.toml": '[observer]\nname = "o"\n[segmenters.ruptures]\nplugin = "hub-threshold"\n'}, ["validate", "o.toml"], ["o.toml:4: key segmenters.ruptures.plugin", "a plugin named inside a plugin's own table"]),
    # -- path search's comparison: the posegraph's tempo (issue 18, gesture18)
    # -- the forward model's travel: an edge's travel in a state file (issue 18, fmtravel)
    ("state-edge-travel", "a learned edge whose travel is not one row per frame of its demonstration", {"st.json": state(actors={"max": {"character": "Max", "components": {"motor": {"plugin": "motor-command-graph", "state": {"left_wrist": {"nodes": {"n1": [[0.26, 1.4, 0.4]]}, "edges": [{"from": "hub", "to": "n1", "name": "left_wrist:e1", "commands": [{"start": [0.25, 0.92, 0.06], "target": [0.26, 1.4, 0.4], "duration": 0.9}], "shown": [[[0.25, 0.92, 0.06]], [[0.26, 1.4, 0.4]]], "shown_fps": 30.0, "travel": [[0.0, 0.0, 1.0]]}]}}}}}})}, ["run", "imitation_games", "--duration", "0.1", "--load", "st.json"], ["key actors.max.components.motor.state.left_wrist.edges[0].travel: invalid travel", "expected where the body went at each frame of shown"]),
    # -- fmstyled: the forward model's styled comparison: posture, tempo (issue 18, fmstyled)
    # -- observer templates: --observer, [observer] extends (issue 18)
    ("observer-unknown", "an observer template that cannot be found", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--observer", "several-take", "m.bvh"], ["key --observer: cannot find observer template 'several-take'", "available: papers, recordings"]),
    ("observer-extends-cycle", "observer templates extending each other", {"a.toml": '[observer]\nname = "a"\nextends = "b.toml"\n', "b.toml": '[observer]\nname = "b"\nextends = "a.toml"\n'}, ["validate", "a.toml"], ["key observer.extends", "extends cycle: a.toml -> b.toml -> a.toml"]),
    ("observer-extends-character", "an observer template extending a character file", {"o.toml": '[observer]\nname = "o"\nextends = "max"\n'}, ["validate", "o.toml"], ["o.toml: key observer.extends: max.toml is not an observer template (a character file)", "available: papers, recordings"]),
    ("observer-is-character", "a character file named as the observer template", {"p.toml": PROFILE, "m.bvh": BVH}, ["observe", "--body", "p.toml", "--repertoire", ".", "--observer", "max", "m.bvh"], ["key --observer: max.toml is not an observer template (a character file)"]),
    ("observer-extends-parent", "a mistake in the template extended", {"base.toml": '[observer]\nname = "base"\n[matcher]\nplugin = "path-search"\n[matcher.beam]\nk = 0\n', "o.toml": '[observer]\nextends = "base.toml"\nname = "o"\n'}, ["validate", "o.toml"], ["base.toml:6: key matcher.beam.k", "value 0 out of range"]),
]


def run_case(files, args):
    """Run the likeme command in-process in a temporary folder; return (exit status, stderr, folder)."""
    from likeme.cli import main

    with tempfile.TemporaryDirectory() as folder:
        for name, text in files.items():
            Path(folder, name).write_text(text, encoding="utf-8")
        err = io.StringIO()
        cwd = os.getcwd()
        os.chdir(folder)
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                try:
                    status = main(args)
                except SystemExit as exc:
                    status = exc.code
        finally:
            os.chdir(cwd)
        return status, err.getvalue(), os.path.realpath(folder)


@pytest.fixture(autouse=True)
def builtins_only(monkeypatch):
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")


def test_there_are_at_least_40_cases():
    assert len(CASES) >= 40
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_input_fails_with_one_clear_line(case):
    _, _, files, args, fragments = case
    status, err, _ = run_case(files, args)
    assert status == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("likeme: error: "), err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0], f"{fragment!r} not in {lines[0]!r}"


@pytest.mark.parametrize("args, fragment", [
    (["run", "demo", "--duration", "0.1", "--render", "out", "--set", "every=" + "9" * 5000], "key --set.every: "),
    (["run", "demo", "--duration", "0.1", "--render", "out", "--set", "every=-" + "9" * 5000], "key --set.every: "),
    (["run", "demo", "--duration", "0.1", "--render", "out", "--set", "every=" + "1_" * 4400 + "1"], "key --set.every: "),
])
def test_an_integer_of_thousands_of_digits_in_set_names_the_key(args, fragment):
    """Kept out of :data:`CASES` (and so out of docs/errors.md): the command line alone is 5,000 characters."""
    status, err, _ = run_case({}, args)
    assert status == 1 and err.count("\n") == 1 and "Traceback" not in err, err
    assert fragment + "an integer of " in err and "expected an integer of at most 4300 digits" in err, err


def test_an_error_line_shows_terminal_escapes_escaped():
    """No control character of the input reaches the terminal: the line is checked character by character."""
    status, err, _ = run_case({"e.csv": "time,\x1b]0;pwn\x07\x1b[2J_x,b_y\n0,1,2\n"}, ["validate", "e.csv"])
    line = err.rstrip("\n")
    assert status == 1 and line.isprintable() and "\\x1b]0;pwn\\x07" in line, err


def test_a_set_value_holding_a_line_break_is_refused():
    """Kept out of :data:`CASES` (docs/errors.md shows each command on one line): ``--set $'matcher.k=1\\n[x]\\ny=2'``
    was read as ``k = 1`` and a table ``[x]`` silently dropped."""
    files = {"p.toml": PROFILE, "m.bvh": BVH}
    for value in ("matcher.k=1\n[x]\ny=2", "matcher.k=1\r\nz=3", "matcher.k=1\u2028"):
        status, err, _ = run_case(files, ["observe", "--body", "p.toml", "--repertoire", ".", "--set", value, "m.bvh"])
        assert status == 1 and err.count("\n") == 1, err
        assert "key --set: a setting holding a line break" in err and "expected TABLE.KEY=VALUE on one line" in err


def render() -> str:
    """docs/errors.md: the table of error cases with their real messages."""
    out = [
        "# Errors",
        "",
        "Every error a user can cause is one line on standard error, `likeme: error: ...`, with exit status 1, and a",
        "documented exception in Python: `toolkit.ConfigError` for input (files, keys, values, state files),",
        "`toolkit.PluginError` for a plugin that fails (named with the hook or method). Both derive from",
        "`toolkit.LikemeError`. The message names the file (and line where known), the key path, what was expected and",
        "what is available. The table is generated by `python -m tests.likeme.test_errors > docs/errors.md` from the cases",
        "`tests/likeme/test_errors.py` checks; the folder of each case is shown as `DIR`.",
        "",
        "| case | command | message |",
        "| --- | --- | --- |",
    ]
    for name, what, files, args, _ in CASES:
        status, err, folder = run_case(files, args)
        message = err.strip().replace(folder, "DIR").replace(MAX, "characters/max.toml").replace("|", "\\\\|")
        message = re.sub(r"/tmp/[^ :;]+/", "DIR/", message)
        command = ("likeme " + " ".join(args)).replace(MAX, "characters/max.toml")
        out.append(f"| {what} | `{command}` | `{message}` |")
    return "\n".join(out) + "\n"


def test_observe_with_standard_input_closed_is_one_line(tmp_path):
    """`likeme observe -` started with standard input closed (`<&-`): one line, not a traceback, before the observer
    is composed."""
    import os
    import subprocess
    import sys

    (tmp_path / "p.toml").write_text(PROFILE)
    done = subprocess.run([sys.executable, "-m", "likeme", "observe", "--body", "p.toml", "--repertoire", ".", "-"],
                          cwd=tmp_path, capture_output=False, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          stdin=None, preexec_fn=lambda: os.close(0), text=True, timeout=120)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == ["likeme: error: -: standard input is closed; expected frames on "
                                                "standard input (a pipe or a file), or recordings named as files"]


def test_errors_pickle_with_every_field():
    """A worker process (``--jobs``, a Dask cluster) sends its error back whole: class, fields and message."""
    import pickle

    from toolkit.errors import ConfigError, PluginError

    config = ConfigError("bad", file="a/b.toml", key=("matcher", "k"), line=3, column=7, expected="an integer",
                         available=["1", "2"])
    plugin = PluginError("dtw", "Matcher.conclude", "ValueError: x")
    for error in (config, plugin, ConfigError("plain")):
        copy = pickle.loads(pickle.dumps(error))
        assert type(copy) is type(error) and str(copy) == str(error) and vars(copy) == vars(error)


def test_docs_errors_table_is_current():
    assert (ROOT / "docs" / "errors.md").read_text() == render(), "regenerate: python -m tests.likeme.test_errors > docs/errors.md"


if __name__ == "__main__":
    os.environ["LIKEME_DISABLE_PLUGIN_AUTOLOAD"] = "1"
    print(render(), end="")
