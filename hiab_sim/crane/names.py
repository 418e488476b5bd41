"""Names shared by every layer: the independent joints and the actuators, in their one order.

Joints: ``theta1`` [rad] (lift boom), ``theta2`` [rad] (tilt boom), ``xt2`` [m] (telescope
extension), the source's (Petrovic & Mattila 2022) Theta1, Theta2 and telescope extension.
Actuators: ``lift`` (stroke x1), ``tilt`` (x2), ``telescope`` (xt2). Arrays of per-joint or
per-actuator samples use these orders in their last axis.
"""

from __future__ import annotations

#: Independent joints, in the column order of joint samples.
JOINT_NAMES: tuple[str, ...] = ("theta1", "theta2", "xt2")
#: Actuators, in the column order of actuator samples and of an EMLA set.
ACTUATOR_NAMES: tuple[str, ...] = ("lift", "tilt", "telescope")
#: The link that carries the TCP and the load (the telescope's rod, frame {B52}).
TOOL_LINK = "telescope_rod"
#: The body of the crane file that is the load at the tip (``bodies.end_mass``, frame {P32}).
LOAD_BODY = "end_mass"
