#!/usr/bin/env python3
"""Writes generated_models/sedan.mbs.yaml from the hardpoints of /work/shared/reference/sedan.md.

Every body frame is parallel to the chassis frame in the design position (joints about arbitrary
axes are type R: R = I at q = 0), its origin at the joint it hangs on; anchors, centres of mass
and joint offsets are the hardpoints (chassis frame) minus that origin. Left side from the table,
right side by y -> -y. Run: python3 generated_models/tools/make_sedan.py > generated_models/sedan.mbs.yaml
"""
import math

FRONT = (1.388, 0.0, 0.25)   # front suspension frame origin, chassis frame
REAR = (-1.388, 0.0, 0.125)  # rear
RACK = (1.2, 0.0, 0.14)      # steering rack frame origin
LOADED_RADIUS = 0.305        # [m] 0.32 unloaded minus the static deflection, ~3.7 kN / 250 kN/m
# Design position: static tyre deflections (wheel loads 3704 N front, 3854 N rear from the static
# equilibrium test, 250 kN/m) put the wheel centres at 0.30519 m (front) and 0.30458 m (rear)
# above a flat road at z = 0 with the 0.32 m unloaded radius: chassis height and pitch.
CHASSIS_Z0 = 0.17733         # [m] chassis frame origin above the road
CHASSIS_PITCH0 = 0.001617    # [rad] nose down
ARB_DROP = 0.25              # [m] anti-roll bar drop link: chassis lever end straight above the arm point
AXLE = 0.1                   # [m] the axle point (kinematics sensors) outboard of the wheel centre on the spin axis

front = {  # double wishbone, left, front suspension frame
    "spindle": (0.0, 0.7979, -0.1199), "upright_cm": (-0.0224, 0.7470, -0.1118),
    "uca_front": (-0.1, 0.47, 0.105), "uca_rear": (-0.25, 0.51, 0.11), "uca_ball": (-0.04, 0.695, 0.105),
    "uca_cm": (-0.1083, 0.5972, 0.1063),
    "lca_front": (0.2, 0.42, -0.27), "lca_rear": (-0.2, 0.47, -0.265), "lca_ball": (0.0, 0.77, -0.32),
    "lca_cm": (0.0048, 0.6112, -0.2932),
    "strut_chassis": (-0.04, 0.52, 0.23), "strut_arm": (0.0, 0.62, -0.27),
    # Tie rod inner point: the reference's (-0.2, 0.42, -0.12) gives 0.65 rad/m of bump steer
    # (toe -38 mrad at 48 mm rebound), which swamps every load-transfer effect in cornering; moved
    # to where the tie rod follows the arms' motion: toe within 1.1 mrad over +-50 mm of travel.
    "tierod_inner": (-0.2, 0.485, -0.095), "tierod_outer": (-0.15, 0.77, -0.12),
    "arb_arm": (0.06, 0.60, -0.285),  # ours: on the lower arm, inboard of the strut
}
rear = {  # multi-link, left, rear suspension frame
    "spindle": (0.0, 0.8, 0.0), "upright_cm": (0.0, 0.76, 0.0),
    "ua_front": (0.06, 0.397, 0.082), "ua_rear": (-0.157, 0.358, 0.062), "ua_upright": (0.056, 0.714, 0.151),
    "ua_cm": (-0.014, 0.49, 0.098),
    "lat_chassis": (0.036, 0.188, -0.133), "lat_upright": (0.029, 0.692, -0.093),
    "tl_chassis": (0.723, 0.449, -0.072), "tl_upright": (0.0, 0.714, -0.156), "tl_cm": (0.279, 0.543, -0.132),
    "shock_chassis": (0.171, 0.478, 0.315), "shock_arm": (0.181, 0.519, -0.162),
    "spring_chassis": (0.181, 0.491, 0.110), "spring_arm": (0.181, 0.419, -0.164),
    "toe_chassis": (-0.257, 0.170, -0.116), "toe_upright": (-0.144, 0.712, -0.056),
    "arb_arm": (0.279, 0.543, -0.132),  # ours: at the trailing link's centre of mass
}


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def fmt(v):
    """[x, y, z]; a component given as a string (a parameter, `$name` or `-$name`) is written as is."""
    return "[" + ", ".join(x if isinstance(x, str) else f"{x:.12g}" if abs(x) > 1e-12 else "0" for x in v) + "]"


def with_parameter(v, axis, name, sign=1):
    """v with component `axis` replaced by the parameter `name` (negated for sign -1)."""
    return tuple((("-" if sign < 0 else "") + "$" + name) if i == axis else x for i, x in enumerate(v))


def side(points, origin, sign):
    """Chassis-frame hardpoints of one side (sign +1 left, -1 right)."""
    return {k: add(origin, (x, sign * y, z)) for k, (x, y, z) in points.items()}


out = []
w = out.append
w("# The sedan: a full car (Audi A6 class) for the vehicle scenes. Written by")
w("# generated_models/tools/make_sedan.py from /work/shared/reference/sedan.md; docs/models.md, section")
w("# sedan, lists its coordinates, ports and conventions. Chassis frame: x forward, y left, z up;")
w("# every body frame is parallel to it in the design position (all q = 0 but the chassis height).")
w("model: sedan")
w("gravity: [0, 0, -9.81]")
w("parameters:")
w("  chassis_mass: {value: 1400.0, unit: kg}       # sprung mass (A6 class)")
w("  chassis_ixx: {value: 550.0, unit: kg m^2}     # about the centre of mass")
w("  chassis_iyy: {value: 2400.0, unit: kg m^2}")
w("  chassis_izz: {value: 2650.0, unit: kg m^2}")
w("  wheel_mass: {value: 21.103, unit: kg}         # spindle (1.103) with wheel and tyre (20)")
# Suspension geometry kept as symbols (sensitivity directions of the multibody block). Moving a
# mount point holds the spring's free length and the sensors' design lengths: the car settles at
# the ride height the new geometry gives, and the motion ratio changes with the lever.
STRUT_ARM_Y = front["strut_arm"][1] - front["lca_front"][1]
SHOCK_ARM_X = rear["shock_arm"][0] - rear["tl_chassis"][0]
SPRING_ARM_X = rear["spring_arm"][0] - rear["tl_chassis"][0]
CHASSIS_COM_Z = 0.2
w(f"  strut_arm_y_front: {{value: {STRUT_ARM_Y:.12g}, unit: m}}   # front strut's lower mount on the lower arm, outboard of its front pivot (mirrored right)")
w(f"  shock_arm_x_rear: {{value: {SHOCK_ARM_X:.12g}, unit: m}}  # rear damper's lower mount on the trailing link, along x from its pivot (behind it)")
w(f"  spring_arm_x_rear: {{value: {SPRING_ARM_X:.12g}, unit: m}} # rear spring's lower seat on the trailing link, along x from its pivot (behind it)")
w(f"  chassis_com_height: {{value: {CHASSIS_COM_Z:.12g}, unit: m}}  # sprung mass's centre above the chassis frame (the cm sensor stays at 0.2)")
w("bodies:")
wheel_names = {"fl": "front left", "fr": "front right", "rl": "rear left", "rr": "rear right"}

chassis_anchors = {"cm": (0.0, 0.0, 0.2)}
rack_anchors = {}
cuts, loads, sensors = [], [], []
bodies = []

for c, sign in (("fl", 1), ("fr", -1)):
    P = side(front, FRONT, sign)
    chassis_anchors[f"strut_{c}"] = P["strut_chassis"]
    chassis_anchors[f"arb_{c}"] = add(P["arb_arm"], (0, 0, ARB_DROP))
    rack_anchors[f"tierod_{c}"] = sub(P["tierod_inner"], RACK)
    lo = P["lca_front"]
    bodies.append(dict(name=f"lca_{c}", parent="chassis", offset=lo,
                       joints=[dict(name=f"lca_{c}", type="R", axis=sub(P["lca_front"], P["lca_rear"]))],
                       mass=1.611, com=sub(P["lca_cm"], lo), inertia=(0.0151, 0.0207, 0.0355),
                       anchors={"ball": sub(P["lca_ball"], lo),
                                "strut": with_parameter(sub(P["strut_arm"], lo), 1, "strut_arm_y_front", sign),
                                "arb": sub(P["arb_arm"], lo)}))
    uo = P["uca_front"]
    bodies.append(dict(name=f"uca_{c}", parent="chassis", offset=uo,
                       joints=[dict(name=f"uca_{c}", type="R", axis=sub(P["uca_front"], P["uca_rear"]))],
                       mass=1.032, com=sub(P["uca_cm"], uo), inertia=(0.00591, 0.00190, 0.00769),
                       anchors={"ball": sub(P["uca_ball"], uo)}))
    bo = P["lca_ball"]
    bodies.append(dict(name=f"upright_{c}", parent=f"lca_{c}", offset=sub(bo, lo),
                       joints=[dict(name=f"upright_{c}_{a}", type=f"R{a}") for a in "xyz"],
                       mass=1.397, com=sub(P["upright_cm"], bo), inertia=(0.0138, 0.0146, 0.00283),
                       anchors={"ball": sub(P["uca_ball"], bo), "tierod": sub(P["tierod_outer"], bo),
                                "contact": add(sub(P["spindle"], bo), (0, 0, -LOADED_RADIUS))}))
    bodies.append(dict(name=f"wheel_{c}", parent=f"upright_{c}", offset=sub(P["spindle"], bo),
                       joints=[dict(name=f"spin_{c}", type="Ry")],
                       mass="wheel", inertia=(0.6, 1.0, 0.6), anchors={"centre": (0, 0, 0), "axle": (0, AXLE * sign, 0)}))
    cuts.append(f"  - {{name: ball_joint_{c}, type: ball, a: uca_{c}.ball, b: upright_{c}.ball}}")
    cuts.append(f"  - {{name: tie_rod_{c}, type: distance, a: rack.tierod_{c}, b: upright_{c}.tierod, "
                f"length: {norm(sub(P['tierod_outer'], P['tierod_inner'])):.17g}}}")

for c, sign in (("rl", 1), ("rr", -1)):
    P = side(rear, REAR, sign)
    for k in ("shock", "spring", "lat", "toe"):
        chassis_anchors[f"{k}_{c}" if k not in ("lat",) else f"lateral_{c}"] = P[f"{k}_chassis"]
    chassis_anchors[f"arb_{c}"] = add(P["arb_arm"], (0, 0, ARB_DROP))
    ao = P["ua_front"]
    bodies.append(dict(name=f"upper_arm_{c}", parent="chassis", offset=ao,
                       joints=[dict(name=f"upper_arm_{c}", type="R", axis=sub(P["ua_front"], P["ua_rear"]))],
                       mass=4.744, com=sub(P["ua_cm"], ao), inertia=(0.0237, 0.0294, 0.00612),
                       anchors={}))
    uo = P["ua_upright"]
    bodies.append(dict(name=f"upright_{c}", parent=f"upper_arm_{c}", offset=sub(uo, ao),
                       joints=[dict(name=f"upright_{c}_{a}", type=f"R{a}") for a in "xyz"],
                       mass=3.201, com=sub(P["upright_cm"], uo), inertia=(0.0250, 0.00653, 0.0284),
                       anchors={"lateral": sub(P["lat_upright"], uo), "toe": sub(P["toe_upright"], uo),
                                "trailing": sub(P["tl_upright"], uo),
                                "contact": add(sub(P["spindle"], uo), (0, 0, -LOADED_RADIUS))}))
    to = P["tl_chassis"]
    bodies.append(dict(name=f"trailing_{c}", parent="chassis", offset=to,
                       joints=[dict(name=f"trailing_{c}_pitch", type="Ry"), dict(name=f"trailing_{c}_yaw", type="Rz")],
                       mass=15.204, com=sub(P["tl_cm"], to), inertia=(0.0762, 0.527, 0.567),
                       anchors={"upright": sub(P["tl_upright"], to),
                                "shock": with_parameter(sub(P["shock_arm"], to), 0, "shock_arm_x_rear"),
                                "spring": with_parameter(sub(P["spring_arm"], to), 0, "spring_arm_x_rear"),
                                "arb": sub(P["arb_arm"], to)}))
    bodies.append(dict(name=f"wheel_{c}", parent=f"upright_{c}", offset=sub(P["spindle"], uo),
                       joints=[dict(name=f"spin_{c}", type="Ry")],
                       mass="wheel", inertia=(0.6, 1.0, 0.6), anchors={"centre": (0, 0, 0), "axle": (0, AXLE * sign, 0)}))
    cuts.append(f"  - {{name: trailing_joint_{c}, type: ball, a: trailing_{c}.upright, b: upright_{c}.trailing}}")
    cuts.append(f"  - {{name: lateral_link_{c}, type: distance, a: chassis.lateral_{c}, b: upright_{c}.lateral, "
                f"length: {norm(sub(P['lat_upright'], P['lat_chassis'])):.17g}}}")
    cuts.append(f"  - {{name: toe_link_{c}, type: distance, a: chassis.toe_{c}, b: upright_{c}.toe, "
                f"length: {norm(sub(P['toe_upright'], P['toe_chassis'])):.17g}}}")

# chassis: free body (x, y, z in the ground frame, then yaw, pitch, roll)
w("  - name: chassis")
w("    joints:")
w("      - {name: x, type: Tx}")
w("      - {name: y, type: Ty}")
w(f"      - {{name: z, type: Tz, initial: {CHASSIS_Z0}}}")
w("      - {name: yaw, type: Rz}")
w(f"      - {{name: pitch, type: Ry, initial: {CHASSIS_PITCH0}}}")
w("      - {name: roll, type: Rx}")
w("    mass: $chassis_mass")
w("    com: [0, 0, $chassis_com_height]")
w("    inertia: [$chassis_ixx, $chassis_iyy, $chassis_izz]")
w("    anchors:")
for k, v in chassis_anchors.items():
    w(f"      {k}: {fmt(v)}")
w("  - name: rack")
w("    parent: chassis")
w(f"    offset: {fmt(RACK)}")
w("    joints: [{name: rack, type: Ty, driven: true}]")
w("    mass: 2.0")
w("    inertia: [0.05, 0.001, 0.05]")
w("    anchors:")
for k, v in rack_anchors.items():
    w(f"      {k}: {fmt(v)}")
for b in bodies:
    w(f"  - name: {b['name']}")
    w(f"    parent: {b['parent']}")
    w(f"    offset: {fmt(b['offset'])}")
    js = []
    for j in b["joints"]:
        extra = f", axis: {fmt(j['axis'])}" if "axis" in j else ""
        js.append(f"{{name: {j['name']}, type: {j['type']}{extra}}}")
    w("    joints: [" + ", ".join(js) + "]")
    if b["mass"] == "wheel":
        w("    mass: {value: 0, fold: true}" if False else "    mass: $wheel_mass")
    else:
        w(f"    mass: {b['mass']}")
    if "com" in b:
        w(f"    com: {fmt(b['com'])}")
    w(f"    inertia: {fmt(b['inertia'])}")
    if b["anchors"]:
        w("    anchors: {" + ", ".join(f"{k}: {fmt(v)}" for k, v in b["anchors"].items()) + "}")
w("cuts:")
out.extend(cuts)

# Inputs. Link forces along spring, damper and drop-link lines (the spring blocks' compression-
# positive and the dampers' tension-positive conventions); tyre forces at the contact point under
# the wheel centre (on the upright: the bearing passes every component but the spin torque,
# which the wheel_torque port carries: -loaded radius * fx plus drive or brake torque).
struts = {"fl": ("strut_fl", "lca_fl", "strut", "strut"), "fr": ("strut_fr", "lca_fr", "strut", "strut"),
          "rl": ("spring_rl", "trailing_rl", "spring", "shock"), "rr": ("spring_rr", "trailing_rr", "spring", "shock")}
design = {}
for c, sign in (("fl", 1), ("fr", -1), ("rl", 1), ("rr", -1)):
    if c[0] == "f":
        P = side(front, FRONT, sign)
        design[f"spring_{c}"] = norm(sub(P["strut_arm"], P["strut_chassis"]))
        design[f"damper_{c}"] = design[f"spring_{c}"]
        design[f"arb_{c}"] = ARB_DROP
        arm, spring_a, damper_a = f"lca_{c}", f"chassis.strut_{c}", f"chassis.strut_{c}"
        spring_b = damper_b = f"lca_{c}.strut"
    else:
        P = side(rear, REAR, sign)
        design[f"spring_{c}"] = norm(sub(P["spring_arm"], P["spring_chassis"]))
        design[f"damper_{c}"] = norm(sub(P["shock_arm"], P["shock_chassis"]))
        design[f"arb_{c}"] = ARB_DROP
        arm = f"trailing_{c}"
        spring_a, damper_a = f"chassis.spring_{c}", f"chassis.shock_{c}"
        spring_b, damper_b = f"{arm}.spring", f"{arm}.shock"
    design[c] = (arm, spring_a, spring_b, damper_a, damper_b)
w("loads:")
for c in ("fl", "fr", "rl", "rr"):
    arm, sa, sb, da, db = design[c]
    w(f"  - {{name: spring_{c}, type: link_force, a: {sa}, b: {sb}, sense: compression}}")
    w(f"  - {{name: damper_{c}, type: link_force, a: {da}, b: {db}, sense: tension}}")
    w(f"  - {{name: arb_{c}, type: link_force, a: chassis.arb_{c}, b: {arm}.arb, sense: compression}}")
    w(f"  - {{name: tyre_fz_{c}, type: force, point: upright_{c}.contact, frame: ground, components: [z]}}")
    w(f"  - {{name: tyre_fx_{c}, type: force, point: upright_{c}.contact, frame: upright_{c}, components: [x]}}")
    w(f"  - {{name: tyre_fy_{c}, type: force, point: upright_{c}.contact, frame: upright_{c}, components: [y]}}")
    w(f"  - {{name: wheel_torque_{c}, type: torque, body: wheel_{c}, frame: upright_{c}, components: [y], "
      f"reaction: upright_{c}}}")
w("sensors:")
w("  - {name: body_acc_z, type: acceleration, point: chassis.cm, frame: chassis, components: [z]}")
w("  - {name: body_acc_y, type: acceleration, point: chassis.cm, frame: chassis, components: [y]}")
w("  - {name: body_acc_x, type: acceleration, point: chassis.cm, frame: chassis, components: [x]}")
w("  - {name: body_acc_z_ground, type: acceleration, point: chassis.cm, frame: ground, components: [z]}")
w("  - {name: body_vx, type: velocity, point: chassis.cm, frame: chassis, components: [x]}")
w("  - {name: body_vy, type: velocity, point: chassis.cm, frame: chassis, components: [y]}")
w("  - {name: body_vz, type: velocity, point: chassis.cm, frame: chassis, components: [z]}")
w("  - {name: body_pos, type: position, point: chassis.cm}")
w("  - {name: yaw_rate, type: angular_velocity, body: chassis, frame: chassis, components: [z]}")
w("  - {name: roll_rate, type: angular_velocity, body: chassis, frame: chassis, components: [x]}")
w("  - {name: pitch_rate, type: angular_velocity, body: chassis, frame: chassis, components: [y]}")
w("  - {name: roll, type: joint, joint: roll, components: [q]}")
w("  - {name: pitch, type: joint, joint: pitch, components: [q]}")
w("  - {name: yaw, type: joint, joint: yaw, components: [q]}")
for c in ("fl", "fr", "rl", "rr"):
    arm, sa, sb, da, db = design[c]
    w(f"  - {{name: spring_defl_{c}, type: length, a: {sa}, b: {sb}, sense: compression, "
      f"reference: {design['spring_' + c]:.17g}, components: [length]}}")
    w(f"  - {{name: damper_stroke_{c}, type: length, a: {da}, b: {db}, "
      f"reference: {design['damper_' + c]:.17g}, components: [length]}}")
    w(f"  - {{name: damper_rate_{c}, type: length, a: {da}, b: {db}, components: [rate]}}")
    w(f"  - {{name: arb_travel_{c}, type: length, a: chassis.arb_{c}, b: {arm}.arb, sense: compression, "
      f"reference: {design['arb_' + c]:.17g}, components: [length]}}")
    w(f"  - {{name: wheel_z_{c}, type: position, point: wheel_{c}.centre, components: [z]}}")
    w(f"  - {{name: wheel_zdot_{c}, type: velocity, point: wheel_{c}.centre, components: [z]}}")
    w(f"  - {{name: wheel_vx_{c}, type: velocity, point: wheel_{c}.centre, frame: upright_{c}, components: [x]}}")
    w(f"  - {{name: wheel_vy_{c}, type: velocity, point: wheel_{c}.centre, frame: upright_{c}, components: [y]}}")
    w(f"  - {{name: wheel_omega_{c}, type: angular_velocity, body: wheel_{c}, frame: upright_{c}, components: [y]}}")
    w(f"  - {{name: wheel_pos_{c}, type: position, point: wheel_{c}.centre}}")
# For the kinematics and compliance analyses (dydp kc): a point on each wheel's spin axis, outboard
# of the centre (its direction gives toe and camber), and the contact point (track, roll centre).
for c in ("fl", "fr", "rl", "rr"):
    w(f"  - {{name: axle_pos_{c}, type: position, point: wheel_{c}.axle}}")
    w(f"  - {{name: contact_pos_{c}, type: position, point: upright_{c}.contact}}")
w("# the chassis, the lower arms (front) and trailing links' pitch (rear) for the wheel travel, the spins")
w("independent: [x, y, z, yaw, pitch, roll, lca_fl, lca_fr, trailing_rl_pitch, trailing_rr_pitch, "
  "spin_fl, spin_fr, spin_rl, spin_rr]")
open("/dev/stdout", "w").write("\n".join(out) + "\n")
