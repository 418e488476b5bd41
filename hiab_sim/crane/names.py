"""The crane file format's schema: the one module that spells its fixed section, joint, link and body names.

The crane file (``hiab_sim/presets/hiab_xs031.yaml``) has a fixed topology, the XS 031's: two
closed chains under ``chains`` (``lift``, ``tilt``), a top-level ``telescope`` section, and links
and bodies named after them. Every other module of the crane model (its loader, dataclasses,
kinematics, closed-form dynamics, mounting rows, MJCF builder and converter to a machine
description) takes these names from here; a machine file (:mod:`hiab_sim.machine`) names its own.
The joint and actuator orders are also the sample orders every layer shares.

Joints: ``theta1`` [rad] (lift boom), ``theta2`` [rad] (tilt boom), ``xt2`` [m] (telescope
extension), the source's (Petrovic & Mattila 2022) Theta1, Theta2 and telescope extension.
Actuators: ``lift`` (stroke x1), ``tilt`` (x2), ``telescope`` (xt2). Arrays of per-joint or
per-actuator samples use these orders in their last axis.

Links: ``base`` and, per chain, its boom, cylinder and rod (``<chain>_boom``, ``<chain>_cylinder``,
``<chain>_rod``: :func:`boom_link`, :func:`cylinder_link`, :func:`rod_link`), then the telescope's
rod ``telescope_rod``; see :mod:`hiab_sim.crane.description` for their frames. The ``bodies``
section names its bodies freely; the model refers to two of them by name, the telescope's
cylinder and the load.
"""

from __future__ import annotations

#: The closed chains: keys of the file's ``chains`` section, their actuators and EMLAs.
LIFT = "lift"
TILT = "tilt"
#: The telescope: the file's top-level section, its actuator and EMLA.
TELESCOPE = "telescope"
#: The closed chains, lift first (the order of Xi = [xi_lift, xi_tilt]).
CHAIN_NAMES = (LIFT, TILT)

#: Independent joints: the lift boom's and tilt boom's angles [rad] and the telescope's extension [m].
THETA1 = "theta1"
THETA2 = "theta2"
XT2 = "xt2"
#: Independent joints, in the column order of joint samples.
JOINT_NAMES: tuple[str, ...] = (THETA1, THETA2, XT2)
#: Actuators, in the column order of actuator samples and of an EMLA set.
ACTUATOR_NAMES: tuple[str, ...] = (LIFT, TILT, TELESCOPE)


def boom_link(chain: str) -> str:
    """The boom a closed chain drives: link ``<chain>_boom``."""
    return f"{chain}_boom"


def cylinder_link(chain: str) -> str:
    """A closed chain's cylinder: link ``<chain>_cylinder``."""
    return f"{chain}_cylinder"


def rod_link(chain: str) -> str:
    """A closed chain's rod: link ``<chain>_rod``."""
    return f"{chain}_rod"


#: The fixed link, frame {W}.
BASE = "base"
LIFT_BOOM = boom_link(LIFT)
LIFT_CYLINDER = cylinder_link(LIFT)
LIFT_ROD = rod_link(LIFT)
TILT_BOOM = boom_link(TILT)
TILT_CYLINDER = cylinder_link(TILT)
TILT_ROD = rod_link(TILT)
#: The telescope's rod, frame {B52}: the link that slides by xt2 and carries the TCP.
TELESCOPE_ROD = "telescope_rod"
#: Links in base-to-tip order (each link's parent comes before it).
LINK_NAMES = (
    BASE,
    LIFT_BOOM,
    LIFT_CYLINDER,
    LIFT_ROD,
    TILT_BOOM,
    TILT_CYLINDER,
    TILT_ROD,
    TELESCOPE_ROD,
)
#: The telescope's cylinder: the file's body fixed on the tilt boom, whose frame {P22} the telescope slides in.
TELESCOPE_CYLINDER = "telescope_cylinder"

#: The link that carries the TCP and the load (the telescope's rod, frame {B52}).
TOOL_LINK = TELESCOPE_ROD
#: The body of the crane file that is the load at the tip (``bodies.end_mass``, frame {P32}).
LOAD_BODY = "end_mass"
