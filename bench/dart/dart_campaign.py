#!/usr/bin/python3
"""Physics-engine campaigns for validating `umbmark diagnose` (issue 21).

A differential-drive robot simulated in DART 6.12 (Debian `python3-dartpy`;
run with /usr/bin/python3): a chassis on a free joint, two driven spherical
wheels on revolute joints with velocity actuators (real point contact with
Coulomb friction against the floor), and a castor (a frictionless ball, or a
swivel castor: a fork on a vertical revolute joint with bearing friction and
a trailing castor wheel).  The controller drives each leg, spot turn and arc
on its own odometry (encoder ticks of the TRUE wheel angles, NOMINAL wheel
diameters and wheelbase) and stops it when the odometry says the target is
reached.  Motion capture samples the engine's true pose of the axle midpoint
(or of a marker), adds white noise, and may be late (clock offsets).

One class per physical cause (see CLASSES).  Besides the campaign (manifest
TOML + trajectory CSVs in the contract format) the generator writes
`truth.csv` (one row per motion: the TRUE pose change against ideal rolling
from the true wheel angles, split into start / steady / stop phases) and
`truth.md` (its summary and the expected verdict), the measured evidence for
the expected answer.

Two robot designs (--robot): A, the default (wheelbase 0.26-0.36 m, 4-7 kg,
rear castor); B, a bigger, heavier robot with a front castor and a different
recording (see Config._robot_b).

Usage: dart_campaign.py CLASS[+CLASS] SEED OUTDIR [--quick] [--robot A|B] [--scatter [K]]
"""
import argparse
import math
import os
import sys

import numpy as np
import dartpy as dart

DT = 0.002           # engine step (s); contact is exact sphere-box (DART detector)
RATE = 20.0          # encoder / motion-capture sample rate of squares and back-and-forth runs (Hz)
FREE_RATE = 50.0     # ... of the free paths (figure eights)
FREE_SPEED = 0.2     # m/s along the figure eights
G = 9.81
WHEEL_MU_SWIVEL = 0.275   # castor classes: drive-wheel grip just under the slip threshold
WHEEL_MU_SWIVEL_B = 0.25  # ... of robot B (its threshold: see _apply_class_b)
ROUGH_K = 0.0002          # --scatter: default wheel-ground contact noise k (m^1/2): about 2 mm of return scatter

# Expected verdict per class, decided from the physics (truth.md checks it).
CLASSES = {
    "clean": "none",
    "stop_slide": "stop_slide",
    "swivel_castor": "castor_swivel",
    "offset_castor": "castor_kick+castor_swivel",   # both named (measured: a kick of one sign
                                                    # at every forward start plus one that follows the turn)
    "floor_strips": "bump_outliers",
    "turn_scrub": "turn_scrub",
    "marker_offset": "gt_offset",
    "clock_fixed": "time_offset",
    "clock_per_run": "run_time_offset",
    "eccentric_hubs": "unexplained",
}


def iso(t=(0.0, 0.0, 0.0), yaw=None):
    T = dart.math.Isometry3()
    T.set_identity()
    T.set_translation(np.array(t, float))
    if yaw is not None:
        c, s = math.cos(yaw), math.sin(yaw)
        T.set_rotation(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))
    return T


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def box_inertia(m, x, y, z):
    return np.diag([m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12])


class Config:
    """Everything one campaign is made of, drawn from the class and the seed."""

    def __init__(self, cls, seed, quick, robot="A"):
        rng = np.random.default_rng(seed)
        self.cls, self.seed, self.robot = cls, seed, robot
        self._design_a()
        if robot == "B":
            self._robot_b(rng, quick)
            self._apply_class_b(rng)
            return
        U = rng.uniform
        # Nominal robot (what the odometry uses) -- a robot unlike the bundled one.
        self.b_nom = round(U(0.26, 0.36), 3)
        self.d_nom = round(U(0.09, 0.12), 4)
        self.d_nom_drawn = self.d_nom
        # Fine encoders: the runs of a campaign are identical noise-free copies,
        # and at 2048 ticks/rev their quantisation phases lock in the figure
        # eights (0.5 mm along track over 5 m, read by diagnose as a gap).
        self.ticks = int(rng.choice([8192, 16384]))
        # True robot: wrong diameter ratio and wheelbase in every class (E_d, E_b).
        ed = 1.0 + rng.choice([-1, 1]) * U(0.002, 0.005)
        self.eb = 1.0 + rng.choice([-1, 1]) * U(0.01, 0.03)
        mean_d = self.d_nom             # no common diameter error: E_d and E_b only
        # E_d = D_R / D_L (ratio of true diameters relative to the nominal ratio 1)
        self.r_left = mean_d / 2.0 * 2.0 / (ed + 1.0)
        self.r_right = mean_d / 2.0 * 2.0 / (1.0 / ed + 1.0)
        self.b_true = self.b_nom * self.eb
        self.mass = U(4.0, 7.0)
        # Motion: speeds and accelerations well inside the floor's grip.
        self.v = U(0.25, 0.35)
        self.w = U(0.9, 1.3)
        self.acc = 0.6
        self.alpha = 2.0
        self.hard_stop = False        # wheels stop at once (braked) instead of ramping down
        self.abrupt_turn_start = False
        self.mu = 0.9                 # floor
        self.wheel_mu = 1.5           # wheel tyres (a contact takes the smaller of the two)
        self.castor_mu = 1.5
        self.castor_trail = 0.025
        self.castor = "ball"
        self.castor_y = 0.0
        self.swivel_friction = 0.0
        self.strips = False
        self.ecc = 0.0
        self.marker = (0.0, 0.0)
        self.tau = 0.0
        self.tau_sd = 0.0
        # Motion capture noise (stated in the manifest).
        self.sig_xy = 0.0002
        self.sig_th = 0.0005
        # Campaign size.
        self.side = 1.0
        self.n_square = 2 if quick else 4       # per direction
        self.fb_dist = 1.2
        self.n_fb = 2 if quick else 4
        self.n_free = 2
        self.pause = 0.6
        self.settle = 1.0
        self._apply_class(rng)

    def _design_a(self):
        """Robot A's fixed design and recording (no random draws: A's campaigns
        stay byte-identical to those generated before design B existed)."""
        self.rate = RATE                  # squares and back-and-forth (Hz)
        self.free_rate = FREE_RATE        # figure eights (Hz)
        self.free_speed = FREE_SPEED
        self.eight_radius = 0.6
        self.com = (-0.04, 0.0, 0.01)     # chassis centre of mass from the axle midpoint (m)
        self.chassis_size = (0.40, 0.12)  # length, height of the inertia box (m)
        self.wheel_mass, self.wheel_inertia = 0.4, (8e-4, 1.5e-3, 8e-4)
        self.castor_x, self.castor_r, self.fork_drop = -0.22, 0.02, 0.03
        self.fork = (0.08, (-0.01, 0.0, -0.015), 2e-5)    # mass, centre, inertia of the swivel fork
        self.castor_wheel = (0.05, 1e-5)                  # mass, inertia of the castor wheel
        self.strip_h = (0.006, 0.010)
        self.t_decimals = 2               # time stamps on the sample grid: 10 ms steps are exact
        # A real robot's scatter (--scatter, issue 28; off: campaigns as before)
        self.rough_k = 0.0                # wheel-ground contact noise k [m^1/2]
        self.random_start = False         # random start pose and castor angle per run

    def set_scatter(self, k):
        """A real robot's scatter (issue 28): wheel-ground contact noise (each
        wheel's contact slips by N(0, k^2 |travel|), Driver._roughen), and the
        operator puts the robot down only roughly on the start mark (+-2 cm,
        +-3 deg) with the swivel castor pointing anywhere."""
        self.rough_k = k
        self.random_start = k > 0.0

    def _apply_class(self, rng):
        for c in self.cls.split("+"):
            self._apply_one_class(rng, c)

    def _apply_one_class(self, rng, c):
        U = rng.uniform
        if c == "stop_slide":
            # Hard braking (wheels locked at once) on a low-friction floor; the
            # chassis coasts ~ v^2 / (2 mu_eff g) after legs and turns on after turns.
            self.mu = U(0.55, 0.70)
            self.hard_stop = True
            self.acc, self.alpha = 0.8, 2.0
            self.v = U(0.28, 0.32)
            self.w = U(0.85, 0.95)
        elif c in ("swivel_castor", "offset_castor"):
            # A rubber swivel castor (trail 3 cm, bearing friction) on hard, low-grip
            # drive wheels: when the castor swings back at a start it pulls one
            # wheel past its grip, a brief slip turns the robot.  Without slip
            # (grippy wheels) an ideal castor moves nothing the odometry misses.
            # The slip threshold is sharp (rigid Coulomb contact: below it nothing,
            # 0.02 in grip lower kicks of 10+ mrad), so the robot is fixed and the
            # grip sits just under its threshold (0.29 for this robot).
            self.b_nom, self.d_nom, self.mass, self.ticks = 0.30, 0.10, 5.5, 8192
            self.b_true = self.b_nom * self.eb
            self.r_left, self.r_right = self.r_left / self.d_nom_drawn * 0.10, self.r_right / self.d_nom_drawn * 0.10
            self.castor = "swivel"
            self.mu, self.castor_mu, self.wheel_mu = 1.0, 1.0, WHEEL_MU_SWIVEL
            self.swivel_friction = U(0.14, 0.16)
            self.castor_trail = 0.03
            self.acc = 1.0
            if c == "offset_castor":
                self.castor_y = U(0.025, 0.035) * rng.choice([-1, 1])
        elif c == "floor_strips":
            self.strips = True
        elif c == "turn_scrub":
            # Fast spot turns started at full rate on a slippery floor: the wheels
            # spin up before the chassis follows.
            self.mu = U(0.45, 0.55)
            self.w = U(1.15, 1.3)
            self.abrupt_turn_start = True
            self.acc = 0.4
        elif c == "marker_offset":
            ang = U(0, 2 * math.pi)
            rad = U(0.004, 0.008)
            self.marker = (rad * math.cos(ang), rad * math.sin(ang))
        elif c == "clock_fixed":
            self.tau = U(0.02, 0.04) * rng.choice([-1, 1])
        elif c == "clock_per_run":
            self.tau_sd = U(0.03, 0.04)
        elif c == "eccentric_hubs":
            self.ecc = U(0.0008, 0.0012)
        elif c != "clean":
            raise SystemExit(f"unknown class {c}; one of {', '.join(CLASSES)}")

    def _robot_b(self, rng, quick):
        """Design B: a bigger, heavier robot with its castor in FRONT of the axle,
        the centre of mass ahead of the axle and higher, other encoders, and a
        different recording: motion capture at 30 or 100 Hz for every
        experiment, 0.3-0.5 mm / 0.8-1.5 mrad noise, a bigger square, longer
        back-and-forth runs, bigger and faster figure eights, longer pauses."""
        U = rng.uniform
        self.b_nom = round(U(0.40, 0.55), 3)
        self.d_nom = round(U(0.14, 0.20), 4)
        self.d_nom_drawn = self.d_nom
        self.ticks = int(rng.choice([10000, 20000]))     # 2500-line quadrature encoders (x1, x2 gear)
        ed = 1.0 + rng.choice([-1, 1]) * U(0.002, 0.006)
        self.eb = 1.0 + rng.choice([-1, 1]) * U(0.01, 0.03)
        self.r_left = self.d_nom / 2.0 * 2.0 / (ed + 1.0)
        self.r_right = self.d_nom / 2.0 * 2.0 / (1.0 / ed + 1.0)
        self.b_true = self.b_nom * self.eb
        self.mass = U(12.0, 30.0)
        self.v = U(0.35, 0.5)
        self.w = U(0.6, 1.0)
        self.acc, self.alpha = 0.5, 1.5
        self.hard_stop = False
        self.abrupt_turn_start = False
        self.mu, self.wheel_mu, self.castor_mu = 0.8, 1.2, 1.2
        self.castor_trail = 0.045
        self.castor = "ball"
        self.castor_y = 0.0
        self.swivel_friction = 0.0
        self.strips = False
        self.ecc = 0.0
        self.marker = (0.0, 0.0)
        self.tau = 0.0
        self.tau_sd = 0.0
        self.sig_xy = round(U(0.0003, 0.0005), 5)
        self.sig_th = round(U(0.0008, 0.0015), 5)
        self.rate = float(rng.choice([30.0, 100.0]))
        self.free_rate = self.rate
        self.free_speed, self.eight_radius = 0.3, 0.9
        self.com = (0.06, 0.0, 0.03)
        self.chassis_size = (0.60, 0.20)
        self.castor_x, self.castor_r, self.fork_drop = 0.30, 0.035, 0.05
        self.fork = (0.25, (-0.015, 0.0, -0.025), 1e-4)
        self.castor_wheel = (0.2, 1e-4)
        self.strip_h = (0.010, 0.016)
        self.t_decimals = 4               # 30 Hz stamps are not on a 10 ms grid
        self.side = round(U(1.5, 2.0), 1)
        self.n_square = 2 if quick else 4
        self.fb_dist = 2.0
        self.n_fb = 3 if quick else 6
        self.n_free = 2
        self.pause = 1.0
        self.settle = 1.5

    def _apply_class_b(self, rng):
        """Robot B's physical causes (tuned on B's seed 1 only)."""
        for c in self.cls.split("+"):
            self._apply_one_class_b(rng, c)

    def _apply_one_class_b(self, rng, c):
        U = rng.uniform
        if c == "stop_slide":
            # hard braking on a low-friction floor (the ball castor carries ~20 %)
            self.mu = U(0.60, 0.75)
            self.hard_stop = True
            self.v = U(0.38, 0.42)
            self.w = U(0.70, 0.80)
        elif c in ("swivel_castor", "offset_castor"):
            # front swivel castor with bearing friction on low-grip drive wheels,
            # grip just under this robot's slip threshold.  Measured on seed 1
            # (one square each way): bearing 0.6 N m kicks ~1 mrad at grip 0.20
            # and nothing at 0.25; at grip 0.25, 1.0 / 1.1 / 1.2 N m kick about
            # 6 / 11 / 15 mrad following the turn; grip 0.20 with 1.1 N m also
            # makes the spot turns slip (k 0.08).
            self.b_nom, self.d_nom, self.mass, self.ticks = 0.48, 0.16, 20.0, 10000
            self.b_true = self.b_nom * self.eb
            self.r_left = self.r_left / self.d_nom_drawn * 0.16
            self.r_right = self.r_right / self.d_nom_drawn * 0.16
            self.castor = "swivel"
            self.mu, self.castor_mu, self.wheel_mu = 1.0, 1.0, WHEEL_MU_SWIVEL_B
            self.swivel_friction = U(1.0, 1.15)   # ~0.028 m x the castor load, as robot A
            self.acc = 0.8
            if c == "offset_castor":
                self.castor_y = U(0.04, 0.06) * rng.choice([-1, 1])
        elif c == "floor_strips":
            self.strips = True
        elif c == "turn_scrub":
            self.mu = U(0.45, 0.55)
            self.w = U(0.9, 1.0)
            self.abrupt_turn_start = True
            self.acc = 0.4
        elif c == "marker_offset":
            ang = U(0, 2 * math.pi)
            rad = U(0.006, 0.012)
            self.marker = (rad * math.cos(ang), rad * math.sin(ang))
        elif c == "clock_fixed":
            self.tau = U(0.015, 0.035) * rng.choice([-1, 1])
        elif c == "clock_per_run":
            self.tau_sd = U(0.025, 0.035)
        elif c == "eccentric_hubs":
            self.ecc = U(0.0012, 0.0018)
        elif c != "clean":
            raise SystemExit(f"unknown class {c}; one of {', '.join(CLASSES)}")
        r = self.d_nom / 2
        self.wheel_mass = 1.2
        self.wheel_inertia = (0.25 * 1.2 * r * r, 0.5 * 1.2 * r * r, 0.25 * 1.2 * r * r)


class Robot:
    """The DART world: floor, chassis, two driven wheels, castor."""

    def __init__(self, cfg):
        self.cfg = cfg
        self.world = dart.simulation.World()
        self.world.setTimeStep(DT)
        self.world.setGravity([0.0, 0.0, -G])
        floor = dart.dynamics.Skeleton("floor")
        j, body = floor.createWeldJointAndBodyNodePair()
        self._box(body, (40.0, 40.0, 0.1), (0.0, 0.0, -0.05), cfg.mu)
        self.world.addSkeleton(floor)
        self.r_mean = 0.5 * (cfg.r_left + cfg.r_right)
        self.skel = dart.dynamics.Skeleton("robot")
        fj, self.chassis = self.skel.createFreeJointAndBodyNodePair()
        self.chassis.setInertia(dart.dynamics.Inertia(
            cfg.mass, list(cfg.com), box_inertia(cfg.mass, cfg.chassis_size[0], cfg.b_true, cfg.chassis_size[1])))
        self.wheels = []
        phase = [0.0, 2.1]
        for i, (r, y) in enumerate(((cfg.r_left, cfg.b_true / 2), (cfg.r_right, -cfg.b_true / 2))):
            wj, wb = self.skel.createRevoluteJointAndBodyNodePair(self.chassis)
            wj.setTransformFromParentBodyNode(iso((0.0, y, 0.0)))
            wj.setAxis([0.0, 1.0, 0.0])
            wb.setInertia(dart.dynamics.Inertia(cfg.wheel_mass, [0.0, 0.0, 0.0], np.diag(list(cfg.wheel_inertia))))
            off = (cfg.ecc * math.cos(phase[i]), 0.0, cfg.ecc * math.sin(phase[i]))
            self._sphere(wb, r, off, cfg.wheel_mu)
            wj.setActuatorType(dart.dynamics.RevoluteJoint.ActuatorType.VELOCITY)
            wj.setForceUpperLimit(0, 60.0)
            wj.setForceLowerLimit(0, -60.0)
            self.wheels.append(wj)
        self._castor()
        self.world.addSkeleton(self.skel)
        self.world.getConstraintSolver().setCollisionDetector(dart.collision.DARTCollisionDetector())
        q = self.skel.getPositions()
        q[5] = self.r_mean + 0.0003
        self.skel.setPositions(q)
        self.strips = []

    swivel = None

    @staticmethod
    def _box(body, size, pos, mu):
        sn = body.createShapeNode(dart.dynamics.BoxShape(list(size)))
        sn.setRelativeTransform(iso(pos))
        sn.createCollisionAspect()
        sn.createDynamicsAspect().setFrictionCoeff(mu)

    @staticmethod
    def _sphere(body, r, pos, mu):
        sn = body.createShapeNode(dart.dynamics.SphereShape(r))
        sn.setRelativeTransform(iso(pos))
        sn.createCollisionAspect()
        sn.createDynamicsAspect().setFrictionCoeff(mu)
        return sn

    def _castor(self):
        cfg, rc, xc, drop = self.cfg, self.cfg.castor_r, self.cfg.castor_x, self.cfg.fork_drop
        if cfg.castor == "ball":
            # frictionless ball castor: carries load, no force in the plane
            self._sphere(self.chassis, rc, (xc, cfg.castor_y, -(self.r_mean - rc)), 0.0)
            return
        # swivel castor: vertical swivel axis, fork with trail, castor wheel on an axle
        sj, fork = self.skel.createRevoluteJointAndBodyNodePair(self.chassis)
        sj.setTransformFromParentBodyNode(iso((xc, cfg.castor_y, -self.r_mean + rc + drop)))
        sj.setAxis([0.0, 0.0, 1.0])
        sj.setCoulombFriction(0, cfg.swivel_friction)
        sj.setDampingCoefficient(0, 0.002)
        fork.setInertia(dart.dynamics.Inertia(cfg.fork[0], list(cfg.fork[1]), np.diag([cfg.fork[2]] * 3)))
        cj, cw = self.skel.createRevoluteJointAndBodyNodePair(fork)
        cj.setTransformFromParentBodyNode(iso((-cfg.castor_trail, 0.0, -drop)))
        cj.setAxis([0.0, 1.0, 0.0])
        cw.setInertia(dart.dynamics.Inertia(cfg.castor_wheel[0], [0.0, 0.0, 0.0], np.diag([cfg.castor_wheel[1]] * 3)))
        self._sphere(cw, rc, (0.0, 0.0, 0.0), cfg.castor_mu)
        self.swivel = sj

    def add_strip(self, x, y, yaw, rng):
        """A floor strip (6-10 mm high, 2-4 cm long) across the left wheel's path."""
        sk = dart.dynamics.Skeleton(f"strip{len(self.strips)}_{self.world.getTime():.3f}")
        j, body = sk.createWeldJointAndBodyNodePair()
        h = rng.uniform(*self.cfg.strip_h)
        self._box(body, (rng.uniform(0.02, 0.04), 0.08, h), (0.0, 0.0, h / 2), self.cfg.mu)
        j.setTransformFromParentBodyNode(iso((x, y, 0.0), yaw))
        self.world.addSkeleton(sk)
        self.strips.append(sk)

    def clear_strips(self):
        for sk in self.strips:
            self.world.removeSkeleton(sk)
        self.strips = []

    def pose(self):
        T = self.chassis.getWorldTransform()
        p = T.translation()
        R = T.rotation()
        return p[0], p[1], math.atan2(R[1, 0], R[0, 0])

    def wheel_angles(self):
        return self.wheels[0].getPosition(0), self.wheels[1].getPosition(0)


class Driver:
    """Runs the robot: controller on nominal odometry, history of the truth."""

    def __init__(self, cfg, robot, rng):
        self.cfg, self.robot, self.rng = cfg, robot, rng
        self.hist_t, self.hist_pose, self.hist_wheel = [], [], []
        self.motions = []
        self.prev_turn = 0       # sign of the last spot turn since the last line (0: none)
        self.prev_dir = 0        # drive direction of the last line/arc
        self.unyaw = 0.0
        self.last_yaw = None
        # --scatter: its own random stream, so that the other draws stay as before
        self.srng = np.random.default_rng(cfg.seed + 15485863)
        self.run_starts = []             # (x, y, yaw, castor angle) drawn per run
        self._record()

    def ticks(self):
        a = self.robot.wheel_angles()
        n = self.cfg.ticks
        return [math.floor(x / (2 * math.pi) * n) for x in a]

    def odo_travel(self):
        k = math.pi * self.cfg.d_nom / self.cfg.ticks
        t = self.ticks()
        return t[0] * k, t[1] * k

    def _record(self):
        x, y, th = self.robot.pose()
        if self.last_yaw is not None:
            self.unyaw += wrap(th - self.last_yaw)
        else:
            self.unyaw = th
        self.last_yaw = th
        self.hist_t.append(self.robot.world.getTime())
        self.hist_pose.append((x, y, self.unyaw))
        self.hist_wheel.append(self.robot.wheel_angles())

    def step(self, cmd_l, cmd_r):
        self.robot.wheels[0].setCommand(0, cmd_l)
        self.robot.wheels[1].setCommand(0, cmd_r)
        self.robot.world.step()
        self._record()
        if self.cfg.rough_k > 0.0:
            self._roughen()

    def _roughen(self):
        """Wheel-ground contact noise: after each engine step each wheel's contact
        slips along its rolling direction by N(0, k^2 |travel|), travel that
        wheel's rolling distance in the step (Chong & Kleeman's wheel noise; the
        encoders do not see it). The chassis is moved by the slips at
        position level, about the axle midpoint; velocities and contacts are
        left as they are (changing the wheels' radius instead lifts a wheel off
        the floor whenever it shrinks, and the lost traction shortened every leg
        by 0.2 %)."""
        cfg = self.cfg
        slip = [0.0, 0.0]
        for i, r in enumerate((cfg.r_left, cfg.r_right)):
            travel = abs(self.hist_wheel[-1][i] - self.hist_wheel[-2][i]) * r
            if travel > 0.0:
                slip[i] = cfg.rough_k * math.sqrt(travel) * self.srng.normal()
        if slip == [0.0, 0.0]:
            return
        skel = self.robot.skel
        q = skel.getPositions()
        yaw = self.robot.pose()[2]
        ds, dth = 0.5 * (slip[0] + slip[1]), (slip[1] - slip[0]) / cfg.b_true
        q[2] += dth
        q[3] += ds * math.cos(yaw)
        q[4] += ds * math.sin(yaw)
        skel.setPositions(q)

    def idle(self, seconds):
        for _ in range(int(round(seconds / DT))):
            self.step(0.0, 0.0)

    def place_at_start(self):
        """The operator puts the robot on the start mark (origin, heading 0 of
        the lab) before every run.  Besides being what a UMBmark procedure does,
        A swivel castor is straightened (trailing).  It also
        keeps each run's motions at the same angles to DART's friction
        pyramid (its box friction is not isotropic: up to sqrt(2) more grip
        along the diagonals), so equal causes give equal effects."""
        skel = self.robot.skel
        q = skel.getPositions()
        q[0:6] = [0.0, 0.0, 0.0, 0.0, 0.0, self.robot.r_mean + 0.0003]
        castor = 0.0                                   # castor straightened, trailing
        if self.cfg.random_start:                      # --scatter: put down roughly, castor anywhere
            x, y, yaw = self.srng.uniform(-0.02, 0.02), self.srng.uniform(-0.02, 0.02), self.srng.uniform(-0.05, 0.05)
            castor = self.srng.uniform(-math.pi, math.pi)
            q[2], q[3], q[4] = yaw, x, y
            self.run_starts.append((x, y, yaw, castor))
        skel.setPositions(q)
        skel.setVelocities(np.zeros(skel.getNumDofs()))
        if self.robot.swivel is not None:
            self.robot.swivel.setPosition(0, castor)
        self.prev_turn, self.prev_dir = 0, 0
        self.idle(0.3)      # settles; longer than any clock offset looks back

    def step_index(self):
        return len(self.hist_t) - 1

    def motion(self, kind, d_left, d_right, peak, sign, then=None):
        """Drive nominal wheel travels (d_left, d_right) on odometry -- and then,
        without stopping, the travels `then` (same length; the wheel-speed
        ratio blends over 0.1 m, a figure eight's change of curvature); peak is
        the fastest wheel's top speed (m/s).  Profile: ramp up (unless abrupt),
        ramp down to the target (unless hard stop: wheels braked at once)."""
        cfg = self.cfg
        S = math.hypot(d_left, d_right)
        u1 = (d_left / S, d_right / S)
        u2 = u1 if then is None else (then[0] / S, then[1] / S)
        total = S if then is None else 2 * S
        blend = 0.05 * math.sqrt(2.0)
        scale = S / max(abs(d_left), abs(d_right))
        vmax = peak * scale
        if kind == "turn":
            acc = cfg.alpha * cfg.b_nom / 2 * scale
        else:
            acc = cfg.acc * scale
        abrupt = kind == "turn" and cfg.abrupt_turn_start
        start = self.step_index()
        lp, rp = self.odo_travel()
        if kind == "line" and cfg.strips:
            self._place_strips(d_left)
        t, s = 0.0, 0.0
        while True:
            f = min(max((s - (S - blend)) / (2 * blend), 0.0), 1.0) if then is not None else 0.0
            u = ((1 - f) * u1[0] + f * u2[0], (1 - f) * u1[1] + f * u2[1])
            n = math.hypot(u[0], u[1])
            u = (u[0] / n, u[1] / n)
            l, r = self.odo_travel()
            s += (l - lp) * u[0] + (r - rp) * u[1]
            lp, rp = l, r
            rem = total - s
            if rem <= 0.0:
                break
            v = vmax if abrupt else min(vmax, acc * (t + DT))
            if not cfg.hard_stop:
                v = min(v, max(math.sqrt(2.0 * acc * rem), 0.03 * vmax))
            rn = cfg.d_nom / 2
            self.step(v * u[0] / rn, v * u[1] / rn)
            t += DT
            if t > 120.0:
                raise RuntimeError("motion did not finish")
        stop = self.step_index()
        self.idle(cfg.pause)
        self.robot.clear_strips()
        direction = 1 if d_left + d_right >= 0 else -1
        before = "none"
        if kind != "turn":
            if self.prev_turn != 0:
                before = "ccw" if self.prev_turn > 0 else "cw"
            elif self.prev_dir != 0 and self.prev_dir != direction:
                before = "reversal"
            self.prev_dir, self.prev_turn = direction, 0
        else:
            self.prev_turn = sign
        self.motions.append(dict(kind=kind, start=start, stop=stop, end=self.step_index(),
                                 sign=sign, direction=direction, before=before,
                                 v=peak, target=(d_left, d_right)))

    def _place_strips(self, dist):
        x, y, th = self.robot.pose()
        n = self.rng.poisson(0.6 * abs(dist))
        self.n_strips = getattr(self, "n_strips", 0) + n
        sgn = 1.0 if dist >= 0 else -1.0
        b2 = self.cfg.b_true / 2
        for _ in range(n):
            s = sgn * self.rng.uniform(0.15, abs(dist) - 0.1)
            px = x + s * math.cos(th) - b2 * math.sin(th)
            py = y + s * math.sin(th) + b2 * math.cos(th)
            self.robot.add_strip(px, py, th, self.rng)

    # the experiments -------------------------------------------------------
    def line(self, dist):
        self.motion("line", dist, dist, self.cfg.v, 0)

    def turn(self, angle):
        h = angle * self.cfg.b_nom / 2
        self.motion("turn", -h, h, self.cfg.w * self.cfg.b_nom / 2, 1 if angle > 0 else -1)

    def arc(self, radius, angle):
        b2 = self.cfg.b_nom / 2
        dl, dr = angle * (radius - b2), angle * (radius + b2)
        peak = self.cfg.v * max(abs(radius - b2), abs(radius + b2)) / abs(radius)
        self.motion("arc", dl, dr, peak, 0)

    def square(self, ccw):
        for _ in range(4):
            self.line(self.cfg.side)
            self.turn((1 if ccw else -1) * math.pi / 2)

    def back_and_forth(self):
        self.line(self.cfg.fb_dist)
        self.line(-self.cfg.fb_dist)

    def figure_eight(self):
        """Two circles of radius 0.6 m, ccw then cw, without stopping between,
        at 0.2 m/s (robot B: 0.9 m at 0.3 m/s): DART's contact gives a little under sideways load (0.3 mm
        towards the outside at 0.23 m/s^2 in a 0.4 m circle at 0.3 m/s, gone
        when the curve ends), which would otherwise show as a gap of its own."""
        rad, b2 = self.cfg.eight_radius, self.cfg.b_nom / 2
        ang = 2 * math.pi
        peak = self.cfg.free_speed * (rad + b2) / rad
        self.motion("arc", ang * (rad - b2), ang * (rad + b2), peak, 0,
                    then=(ang * (rad + b2), ang * (rad - b2)))


def run_campaign(cfg):
    """Drive every experiment; returns the driver (history) and the runs."""
    rng = np.random.default_rng(cfg.seed + 7919)
    robot = Robot(cfg)
    drv = Driver(cfg, robot, rng)
    drv.idle(1.0)                      # let the robot settle on the floor
    runs = []                          # (experiment, direction, first step, last step)

    def run(exp, direction, body):
        drv.place_at_start()
        first = drv.step_index()
        drv.idle(cfg.settle)
        body()
        drv.idle(cfg.settle - cfg.pause)
        runs.append((exp, direction, first, drv.step_index()))
        drv.idle(0.1)       # still before the next placement (a clock offset looks ahead)

    for i in range(cfg.n_square):
        run("square", "cw", lambda: drv.square(False))
        run("square", "ccw", lambda: drv.square(True))
    for _ in range(cfg.n_fb):
        run("back_and_forth", "fwd_back", drv.back_and_forth)
    for _ in range(cfg.n_free):
        run("free", "free", drv.figure_eight)
    drv.runs = runs
    return drv, runs


def design_tag(cfg):
    return "" if cfg.robot == "A" else f", robot {cfg.robot}"


def write_campaign(cfg, drv, runs, out):
    """Manifest + one trajectory CSV per experiment (contract format)."""
    rng = np.random.default_rng(cfg.seed + 104729)
    t = np.asarray(drv.hist_t)
    pose = np.asarray(drv.hist_pose)
    wheel = np.asarray(drv.hist_wheel)
    # robot A: free paths (arcs) at 50 Hz (more samples where the path curves);
    # samples on the engine's steps
    every_for = {"square": int(round(1.0 / (cfg.rate * DT))), "back_and_forth": int(round(1.0 / (cfg.rate * DT))),
                 "free": int(round(1.0 / (cfg.free_rate * DT)))}
    rate_for = {"square": cfg.rate, "back_and_forth": cfg.rate, "free": cfg.free_rate}
    files = {"square": "square.csv", "back_and_forth": "fwd_back.csv", "free": "free.csv"}
    rows = {k: [] for k in files}
    counts = {k: 0 for k in files}
    mx, my = cfg.marker
    for exp, direction, first, last in runs:
        counts[exp] += 1
        run_no = counts[exp]
        if cfg.robot == "A":
            idx = np.arange(first, last + 1, every_for[exp])
            tc, wk = t[idx], wheel[idx]
        else:   # robot B: samples at exact multiples of 1 / rate (30 Hz is not on the 2 ms steps)
            tc = t[first] + np.arange(0.0, t[last] - t[first] + 1e-9, 1.0 / rate_for[exp])
            wk = np.stack([np.interp(tc, t, wheel[:, 0]), np.interp(tc, t, wheel[:, 1])], axis=1)
            idx = tc
        tau = cfg.tau + (rng.normal(0.0, cfg.tau_sd) if cfg.tau_sd > 0 else 0.0)
        ts = tc - tau                  # the true time each ground-truth sample shows
        px = np.interp(ts, t, pose[:, 0])
        py = np.interp(ts, t, pose[:, 1])
        pth = np.interp(ts, t, pose[:, 2])
        gx = px + mx * np.cos(pth) - my * np.sin(pth) + rng.normal(0, cfg.sig_xy, len(idx))
        gy = py + mx * np.sin(pth) + my * np.cos(pth) + rng.normal(0, cfg.sig_xy, len(idx))
        gth = pth + rng.normal(0, cfg.sig_th, len(idx))
        # the lab frame: the true pose of the axle midpoint at the run's first
        # sample (the noisy first sample would turn the whole run by its noise)
        x0, y0, th0 = pose[first]
        c, s = math.cos(th0), math.sin(th0)
        dx, dy = gx - x0, gy - y0
        rx, ry, rth = c * dx + s * dy, -s * dx + c * dy, gth - th0
        tk = np.floor(wk / (2 * math.pi) * cfg.ticks).astype(np.int64)
        tk -= tk[0]
        for k in range(len(idx)):
            # 0.1 mm / 0.1 mrad steps: rounding adds 0.03 rms to 0.2 mm / 0.5 mrad noise
            rows[exp].append(f"{run_no},{direction},{tc[k] - t[first]:.{cfg.t_decimals}f},{tk[k, 0]},{tk[k, 1]},"
                             f"{rx[k]:.4f},{ry[k]:.4f},{rth[k]:.4f}")
        if cfg.tau_sd > 0:
            drv.run_taus = getattr(drv, "run_taus", []) + [tau]
    os.makedirs(out, exist_ok=True)
    for exp, name in files.items():
        if not rows[exp]:
            continue
        with open(os.path.join(out, name), "w") as f:
            f.write(f"# DART 6.12 physics campaign, class {cfg.cls}, seed {cfg.seed}{design_tag(cfg)} "
                    "(bench/dart/dart_campaign.py)\n")
            f.write("run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n")
            f.write("\n".join(rows[exp]) + "\n")
    with open(os.path.join(out, "campaign.toml"), "w") as f:
        f.write(f"# DART 6.12 physics campaign: class {cfg.cls}, seed {cfg.seed}{design_tag(cfg)}; "
                f"expected verdict {label(cfg.cls)} (see truth.md)\n")
        f.write("[robot]\n")
        f.write(f"wheelbase_m            = {cfg.b_nom}\n")
        f.write(f"wheel_diameter_left_m  = {cfg.d_nom}\n")
        f.write(f"wheel_diameter_right_m = {cfg.d_nom}\n")
        f.write(f"ticks_per_rev          = {cfg.ticks}\n\n")
        f.write("[ground_truth]\n")
        f.write(f"sigma_xy_m      = {cfg.sig_xy}\n")
        f.write(f"sigma_theta_rad = {cfg.sig_th}\n\n")
        f.write(f'[[experiment]]\nkind   = "square"\nside_m = {cfg.side}\nfile   = "square.csv"\n\n')
        f.write(f'[[experiment]]\nkind       = "back_and_forth"\ndistance_m = {cfg.fb_dist}\n'
                'file       = "fwd_back.csv"\n\n')
        f.write('[[experiment]]\nkind = "free"\nfile = "free.csv"\n')


class Truth:
    """The cause measured on the engine's true poses: per motion phase, the true
    pose change against ideal rolling from the true wheel angles (true wheel
    radii and wheelbase), both in the frame of the phase's start."""

    START = 0.4    # s: the start phase of a motion (where a castor kicks)

    def __init__(self, cfg, drv):
        self.cfg = cfg
        self.pose = np.asarray(drv.hist_pose)
        w = np.asarray(drv.hist_wheel)
        ds_l = np.diff(w[:, 0]) * cfg.r_left
        ds_r = np.diff(w[:, 1]) * cfg.r_right
        self.ds = 0.5 * (ds_l + ds_r)
        self.dth = (ds_r - ds_l) / cfg.b_true

    def residual(self, a, b):
        if b <= a:
            return 0.0, 0.0, 0.0
        th0 = self.pose[a, 2]
        th = th0 + np.concatenate(([0.0], np.cumsum(self.dth[a:b])))
        mid = 0.5 * (th[:-1] + th[1:])
        ix = np.sum(self.ds[a:b] * np.cos(mid - th0))
        iy = np.sum(self.ds[a:b] * np.sin(mid - th0))
        dx, dy = self.pose[b, 0] - self.pose[a, 0], self.pose[b, 1] - self.pose[a, 1]
        c, s = math.cos(th0), math.sin(th0)
        tx, ty = c * dx + s * dy, -s * dx + c * dy
        return tx - ix, ty - iy, (self.pose[b, 2] - th0) - (th[-1] - th0)

    def motions(self, motions):
        rows = []
        n_start = int(round(self.START / DT))
        for m in motions:
            a, b, e = m["start"], m["stop"], m["end"]
            mid = min(a + n_start, b)
            st = self.residual(a, mid)
            sd = self.residual(mid, b)
            sp = self.residual(b, e)
            wh = self.residual(a, e)
            ideal_turn = float(np.sum(self.dth[a:e]))
            rows.append(dict(m, start_res=st, steady_res=sd, stop_res=sp, whole_res=wh,
                             ideal_turn=ideal_turn, travel=float(np.sum(np.abs(self.ds[a:e])))))
        return rows


def fmt_ms(vals, unit_scale, unit, dec=2):
    if len(vals) == 0:
        return "-"
    v = np.asarray(vals) * unit_scale
    sd = v.std(ddof=1) if len(v) > 1 else 0.0
    return f"{v.mean():+.{dec}f}{' ' + unit if unit else ''} (sd {sd:.{dec}f}, n {len(v)})"


def label(cls):
    """The class's expected verdict as labelled (a pair: both effects)."""
    return "+".join(CLASSES[c] for c in cls.split("+"))


def t_value(v):
    v = np.asarray(v, float)
    if len(v) < 2:
        return 0.0
    se = v.std(ddof=1) / math.sqrt(len(v))
    return v.mean() / se if se > 0 else (math.inf if v.mean() != 0 else 0.0)


# A cause measured on the true poses counts when its mean is at least this
# large and 4 standard errors from 0 (mm, mrad, fraction of the turn).
MIN_SLIDE, MIN_TURN_ON, MIN_SCRUB, MIN_KICK, MIN_CLOCK_MM, MIN_MARKER = 1.0e-3, 2.0e-3, 0.005, 2.0e-3, 2.0e-3, 2.0e-3


def measured_causes(cfg, rows, drv):
    """The contract effects the engine actually produced, measured on its true
    poses (slides, scrub, castor kicks) or known from the recording (marker,
    clocks, strips placed); returns [(effect, evidence)] and the expected
    verdict they make (an outside cause, eccentric hubs: `unexplained`)."""
    lines = [r for r in rows if r["kind"] == "line"]
    turns = [r for r in rows if r["kind"] == "turn"]
    moves = [r for r in rows if r["kind"] != "turn"]
    out = []
    slide = [r["stop_res"][0] * r["direction"] for r in lines]
    turn_on = [r["stop_res"][2] * r["sign"] for r in turns]
    if (np.mean(slide) > MIN_SLIDE and t_value(slide) > 4) or (np.mean(turn_on) > MIN_TURN_ON and t_value(turn_on) > 4):
        out.append(("stop_slide", f"slide {np.mean(slide) * 1e3:+.2f} mm, turn-on {np.mean(turn_on) * 1e3:+.2f} mrad"))
    scrub = [-(r["whole_res"][2] * r["sign"]) / abs(r["ideal_turn"]) for r in turns]
    if scrub and np.mean(scrub) > MIN_SCRUB and t_value(scrub) > 4:
        out.append(("turn_scrub", f"k {np.mean(scrub):.4f}"))
    fwd = lambda before: [r["start_res"][2] for r in moves if r["before"] == before and r["direction"] > 0]
    ccw, cw = fwd("ccw"), fwd("cw")
    if len(ccw) > 1 and len(cw) > 1:
        follow = 0.5 * (np.mean(ccw) - np.mean(cw))
        se = 0.5 * math.sqrt(np.var(ccw, ddof=1) / len(ccw) + np.var(cw, ddof=1) / len(cw))
        if follow > MIN_KICK and follow > 4 * se:
            out.append(("castor_swivel", f"start heading after ccw {np.mean(ccw) * 1e3:+.1f}, after cw "
                                         f"{np.mean(cw) * 1e3:+.1f} mrad"))
    kick = [r["start_res"][2] * r["direction"] for r in moves if r["before"] in ("none", "ccw", "cw")]
    if len(kick) > 1 and abs(np.mean(kick)) > MIN_KICK and abs(t_value(kick)) > 4:
        out.append(("castor_kick", f"start heading in the drive direction {np.mean(kick) * 1e3:+.1f} mrad"))
    if getattr(drv, "n_strips", 0) > 0:
        out.append(("bump_outliers", f"{drv.n_strips} strips under the left wheel"))
    if math.hypot(*cfg.marker) > MIN_MARKER:
        out.append(("gt_offset", f"marker {math.hypot(*cfg.marker) * 1e3:.1f} mm off"))
    if abs(cfg.tau) * cfg.v > MIN_CLOCK_MM:
        out.append(("time_offset", f"v tau {abs(cfg.tau) * cfg.v * 1e3:.1f} mm"))
    taus = getattr(drv, "run_taus", [])
    if len(taus) > 1 and np.std(taus, ddof=1) * cfg.v > MIN_CLOCK_MM:
        out.append(("run_time_offset", f"v tau_sd {np.std(taus, ddof=1) * cfg.v * 1e3:.1f} mm"))
    if cfg.ecc > 0:
        return out, "unexplained"
    return out, "+".join(e for e, _ in out) or "none"


def return_scatter(drv):
    """Run-to-run scatter of the TRUE return pose of runs of one experiment and
    direction (in each run's start frame): mean over the groups of sqrt(var x + var y)."""
    pose = np.asarray(drv.hist_pose)
    groups = {}
    for exp, direction, first, last in getattr(drv, "runs", []):
        x0, y0, th0 = pose[first]
        dx, dy = pose[last, 0] - x0, pose[last, 1] - y0
        c, s = math.cos(th0), math.sin(th0)
        groups.setdefault((exp, direction), []).append((c * dx + s * dy, -s * dx + c * dy))
    sds = [math.sqrt(np.var([p[0] for p in g], ddof=1) + np.var([p[1] for p in g], ddof=1))
           for g in groups.values() if len(g) > 1]
    return float(np.mean(sds)) if sds else 0.0


def write_truth(cfg, rows, out, drv):
    with open(os.path.join(out, "truth.csv"), "w") as f:
        f.write("# per motion: TRUE pose change minus ideal rolling from the true wheel angles "
                "(frame of the phase start); mm and mrad\n")
        f.write("motion,kind,direction,sign,before,start_along_mm,start_heading_mrad,"
                "steady_along_mm,steady_heading_mrad,stop_along_mm,stop_lateral_mm,"
                "stop_heading_mrad,whole_along_mm,whole_lateral_mm,whole_heading_mrad\n")
        for i, r in enumerate(rows):
            st, sd, sp, wh = r["start_res"], r["steady_res"], r["stop_res"], r["whole_res"]
            f.write(f"{i + 1},{r['kind']},{r['direction']},{r['sign']},{r['before']},"
                    f"{st[0] * 1e3:.3f},{st[2] * 1e3:.3f},{sd[0] * 1e3:.3f},{sd[2] * 1e3:.3f},"
                    f"{sp[0] * 1e3:.3f},{sp[1] * 1e3:.3f},{sp[2] * 1e3:.3f},"
                    f"{wh[0] * 1e3:.3f},{wh[1] * 1e3:.3f},{wh[2] * 1e3:.3f}\n")
    lines = [r for r in rows if r["kind"] == "line"]
    turns = [r for r in rows if r["kind"] == "turn"]
    slide = [r["stop_res"][0] * r["direction"] for r in lines]
    turn_on = [r["stop_res"][2] * r["sign"] for r in turns]
    scrub = [-(r["whole_res"][2] * r["sign"]) / abs(r["ideal_turn"]) for r in turns]
    per_m = [r["steady_res"][0] * r["direction"] / max(r["travel"], 1e-9) for r in lines]
    L = []
    L.append(f"# Measured cause: class `{cfg.cls}`, seed {cfg.seed}{design_tag(cfg)}\n")
    if cfg.rough_k > 0 or "+" in cfg.cls:
        # with a real robot's scatter or two causes: the answer the engine's causes make
        causes, expected = measured_causes(cfg, rows, drv)
        L.append(f"Expected verdict: **{expected}**\n")
        L.append(f"Class label: {label(cfg.cls)}; causes measured in the engine: "
                 + ("; ".join(f"{e} ({ev})" for e, ev in causes) or "none") + ".\n")
        L.append(f"Scatter: wheel-ground contact noise k {cfg.rough_k:.5f} m^1/2; true return scatter {return_scatter(drv) * 1e3:.2f} mm "
                 "(runs of one experiment and direction); start pose and castor angle per run: "
                 + ", ".join(f"({x * 1e3:+.0f} mm, {y * 1e3:+.0f} mm, {yaw * 1e3:+.0f} mrad, castor {c:+.2f} rad)"
                             for x, y, yaw, c in drv.run_starts[:4]) + (" ..." if len(drv.run_starts) > 4 else "")
                 + ".\n")
    else:
        L.append(f"Expected verdict: **{CLASSES[cfg.cls]}**\n")
    L.append("Robot (true vs nominal): wheelbase "
             f"{cfg.b_true:.4f} m vs {cfg.b_nom} (E_b {cfg.eb:.4f}); wheel diameters "
             f"{2 * cfg.r_left:.5f} / {2 * cfg.r_right:.5f} m vs {cfg.d_nom} "
             f"(E_d {cfg.r_right / cfg.r_left:.5f}); {cfg.ticks} ticks/rev; floor mu {cfg.mu:.2f}; "
             f"castor {cfg.castor}" + (f" at y {cfg.castor_y * 1e3:+.0f} mm, swivel friction "
                                       f"{cfg.swivel_friction:.3f} N m" if cfg.castor != "ball" else "")
             + f"; v {cfg.v:.3f} m/s, w {cfg.w:.2f} rad/s; hard stops {cfg.hard_stop}; "
             f"abrupt turn starts {cfg.abrupt_turn_start}.\n")
    if cfg.robot != "A":
        L.append(f"Design {cfg.robot}: mass {cfg.mass:.1f} kg, centre of mass at ({cfg.com[0]:+.2f}, "
                 f"{cfg.com[2]:+.2f}) m from the axle midpoint (forward, up), castor at x {cfg.castor_x:+.2f} m; "
                 f"square side {cfg.side} m, back-and-forth {cfg.fb_dist} m, figure eights of "
                 f"{cfg.eight_radius} m circles at {cfg.free_speed} m/s; pauses {cfg.pause} s; "
                 f"motion capture at {cfg.rate:g} Hz ({cfg.free_rate:g} Hz on the figure eights).\n")
    L.append(f"Motion capture: white noise {cfg.sig_xy * 1e3:.2f} mm, {cfg.sig_th * 1e3:.2f} mrad; "
             f"marker at ({cfg.marker[0] * 1e3:+.2f}, {cfg.marker[1] * 1e3:+.2f}) mm; clock offset "
             f"{cfg.tau * 1e3:+.1f} ms (v tau = {cfg.v * cfg.tau * 1e3:+.2f} mm); per-run clock sd "
             f"{cfg.tau_sd * 1e3:.1f} ms"
             + (f" (drawn: {', '.join(f'{x * 1e3:+.1f}' for x in getattr(drv, 'run_taus', []))} ms)"
                if cfg.tau_sd > 0 else "") + ".\n")
    L.append("True pose change minus ideal rolling from the true wheel angles "
             "(mean, sd, count):\n")
    L.append(f"- slide after a leg (stop phase, along travel): {fmt_ms(slide, 1e3, 'mm')}")
    L.append(f"- turn-on after a spot turn (stop phase, in its sense): {fmt_ms(turn_on, 1e3, 'mrad')}")
    L.append(f"- spot-turn deficit k = 1 - true/ideal heading change: {fmt_ms(scrub, 1.0, '', 4)}")
    L.append(f"- steady legs, along travel per metre: {fmt_ms(per_m, 1e3, 'mm/m')}")
    for before in ("ccw", "cw", "reversal", "none"):
        for d in (1, -1):
            k = [r["start_res"][2] for r in lines + [x for x in rows if x["kind"] == "arc"]
                 if r["before"] == before and r["direction"] == d]
            if k:
                L.append(f"- heading at the start of a {'forward' if d > 0 else 'backward'} "
                         f"motion after {before}: {fmt_ms(k, 1e3, 'mrad')}")
    wh_al = [r["whole_res"][0] for r in lines]
    wh_th = [r["whole_res"][2] for r in rows]
    L.append(f"- whole motion (start to next start), legs along: {fmt_ms(wh_al, 1e3, 'mm')}; "
             f"all motions heading: {fmt_ms(wh_th, 1e3, 'mrad')}")
    L.append("")
    with open(os.path.join(out, "truth.md"), "w") as f:
        f.write("\n".join(L))
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cls", help="a class (" + ", ".join(CLASSES) + ") or two joined by '+' (two causes at once)")
    ap.add_argument("seed", type=int)
    ap.add_argument("out")
    ap.add_argument("--quick", action="store_true", help="half-size campaign (for the committed tests)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a Config attribute (exploring the physics)")
    ap.add_argument("--rate", type=float, default=None,
                    help="sample rate of the squares and back-and-forth runs (Hz; default: the design's)")
    ap.add_argument("--robot", choices=("A", "B"), default="A",
                    help="robot design: A (default; the committed campaigns) or B (bigger, heavier, "
                         "front castor, recorded at 30 or 100 Hz)")
    ap.add_argument("--scatter", nargs="?", type=float, const=ROUGH_K, default=0.0, metavar="K",
                    help=f"a real robot's scatter: wheel-ground contact noise K m^1/2 (default "
                         f"{ROUGH_K}), random start pose and castor angle per run; the expected verdict is "
                         "then decided from the causes measured in the engine")
    a = ap.parse_args()
    for c in a.cls.split("+"):
        if c not in CLASSES:
            raise SystemExit(f"unknown class {c}; one of {', '.join(CLASSES)}")
    cfg = Config(a.cls, a.seed, a.quick, a.robot)
    cfg.set_scatter(a.scatter)
    if a.rate is not None:
        cfg.rate = a.rate
    for kv in a.set:
        k, v = kv.split("=", 1)
        if not hasattr(cfg, k):
            raise SystemExit(f"--set: no attribute {k}")
        setattr(cfg, k, type(getattr(cfg, k))(float(v)) if not isinstance(getattr(cfg, k), str) else v)
    drv, runs = run_campaign(cfg)
    write_campaign(cfg, drv, runs, a.out)
    rows = Truth(cfg, drv).motions(drv.motions)
    print(write_truth(cfg, rows, a.out, drv))


if __name__ == "__main__":
    sys.exit(main())
