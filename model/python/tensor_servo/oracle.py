"""The independent oracle: Pinocchio (the ``pin`` wheel) built from a Chain.

Each joint becomes a 1-DOF Pinocchio joint (RevoluteUnaligned / PrismaticUnaligned about the unit
axis) placed at ``origin_i`` relative to its parent joint (joint 0: ``base * origin_0`` relative to
the root); the tool is an operational frame on the last joint.  Pinocchio's joint value is
``scale_i * q_i``, so its Jacobian columns are multiplied by ``scale_i`` here.  Pinocchio's twists
are (v; omega); this module returns (omega; v) like the rest of tensor-servo.
"""
from __future__ import annotations

import numpy as np
import pinocchio as pin

from .chain import Chain, Pose


def _se3(p: Pose) -> pin.SE3:
    w, x, y, z = p.quat_wxyz
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.asarray(p.xyz, dtype=float))


class PinChain:
    """A Pinocchio model and data for a Chain (serial or a tree), with its tips as frames (the
    tool of a serial chain is tip 0)."""

    def __init__(self, chain: Chain):
        self.chain = chain
        m = pin.Model()
        m.name = chain.name
        jid = [0]  # Pinocchio joint id of each frame index 0..n (0: the universe = root)
        for i, (j, pf) in enumerate(zip(chain.joints, chain.parent_frames())):
            placement = _se3(j.origin)
            if pf == 0:
                placement = _se3(chain.base) * placement  # the base frame is not a joint
            axis = np.asarray(j.axis, dtype=float)
            jm = pin.JointModelPrismaticUnaligned(axis) if j.prismatic else pin.JointModelRevoluteUnaligned(axis)
            jid.append(m.addJoint(jid[pf], jm, placement, j.name))
            m.appendBodyToJoint(jid[-1], pin.Inertia.Identity(), pin.SE3.Identity())
        idx = {j.name: i for i, j in enumerate(chain.joints)}
        self.tip_ids = [m.addFrame(pin.Frame(t.name, jid[idx[t.parent] + 1], _se3(t.pose), pin.FrameType.OP_FRAME))
                        for t in chain.tip_list()]
        self.tool_id = self.tip_ids[0]
        self.model = m
        self.data = m.createData()
        self.scales = chain.scales

    def tool_pose(self, q: np.ndarray, tip: int = 0) -> np.ndarray:
        """4x4 pose of the tool (or of tip ``tip``) in the root frame."""
        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, float) * self.scales)
        return self.data.oMf[self.tip_ids[tip]].homogeneous.copy()

    def joint_poses(self, q: np.ndarray) -> np.ndarray:
        """(n, 4, 4): pose of every joint frame after its motion, in the root frame."""
        pin.forwardKinematics(self.model, self.data, np.asarray(q, float) * self.scales)
        return np.array([self.data.oMi[i].homogeneous for i in range(1, self.model.njoints)])

    def jacobian(self, q: np.ndarray, basis: str = "base", tip: int = 0) -> np.ndarray:
        """(6, n) Jacobian of the tool (tip) origin, rows (omega; v); basis 'base' (root axes) or
        'tool' (the tip's own axes)."""
        rf = {"base": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, "tool": pin.ReferenceFrame.LOCAL}[basis]
        qq = np.asarray(q, float) * self.scales
        pin.computeJointJacobians(self.model, self.data, qq)
        pin.framesForwardKinematics(self.model, self.data, qq)
        J = np.reshape(pin.getFrameJacobian(self.model, self.data, self.tip_ids[tip], rf), (6, -1))
        return np.vstack([J[3:], J[:3]]) * self.scales[None, :]
