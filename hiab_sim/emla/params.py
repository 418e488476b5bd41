"""EMLA parameters: the frozen dataclasses of one EMLA (PMSM, screw, transmission, options), validated when built."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from hiab_sim.checks import check_fields, check_positive, check_range
from hiab_sim.emla.brake import HoldingBrake
from hiab_sim.emla.drive_stiffness import DriveStiffness
from hiab_sim.emla.electrothermal import WindingResistance
from hiab_sim.emla.losses import DriveLosses
from hiab_sim.emla.thermal import ThermalParams
from hiab_sim.errors import InvalidInputError


@dataclass(frozen=True)
class PmsmParams:
    """Permanent-magnet synchronous motor in the dq frame (eqs. ``dq0voltage``, ``torque_torque``).

    Attributes:
        pole_pairs: Number of pole pairs p [-], a positive integer.
        flux_linkage: Permanent-magnet flux linkage Phi_PM [Wb].
        stator_resistance: Stator resistance per phase R_s [ohm].
        Ld: d-axis inductance [H].
        Lq: q-axis inductance [H].
        rated_speed_rpm: Rated (maximum continuous) motor speed [rev/min].
        rated_torque: Rated motor torque [N m] (reported, not a limit of the envelope).
        peak_torque: Peak motor torque tau_peak [N m], a limit of the envelope.
        rotor_inertia: Rotor inertia J_m [kg m^2] (with the gearbox input side).
        rotor_coulomb_friction: Rotor Coulomb friction torque tau_f [N m].
        max_line_voltage_rms: Largest line-to-line rms voltage the inverter applies [V].
        friction_smoothing_speed: omega_eps [rad/s] of the regularised Coulomb friction
            tau_f tanh(omega_m / omega_eps); a model choice, not a motor datum.
        label: Prefix used in error messages.

    """

    pole_pairs: int
    flux_linkage: float
    stator_resistance: float
    Ld: float
    Lq: float
    rated_speed_rpm: float
    rated_torque: float
    peak_torque: float
    rotor_inertia: float
    rotor_coulomb_friction: float
    max_line_voltage_rms: float
    friction_smoothing_speed: float
    label: str = "pmsm"

    def __post_init__(self) -> None:
        pp = self.pole_pairs
        if isinstance(pp, bool) or not isinstance(pp, int) or pp <= 0:
            raise InvalidInputError(f"{self.label}.pole_pairs", pp, "must be a positive integer")
        check_fields(
            self, positive={"flux_linkage": "Wb", "Ld": "H", "Lq": "H"}, non_negative={"stator_resistance": "ohm"}
        )
        check_fields(
            self,
            positive={"rated_speed_rpm": "rev/min", "rated_torque": "N m", "peak_torque": "N m"},
            non_negative={"rotor_inertia": "kg m^2", "rotor_coulomb_friction": "N m"},
        )
        if self.rotor_coulomb_friction >= self.peak_torque:
            raise InvalidInputError(
                f"{self.label}.rotor_coulomb_friction",
                self.rotor_coulomb_friction,
                f"must be < peak_torque = {self.peak_torque:g} N m",
                "N m",
            )
        check_fields(self, positive={"max_line_voltage_rms": "V", "friction_smoothing_speed": "rad/s"})

    @property
    def rated_speed(self) -> float:
        """Rated motor speed [rad/s]."""
        return self.rated_speed_rpm * 2.0 * math.pi / 60.0

    @property
    def torque_constant(self) -> float:
        """K_t = 3/2 p Phi_PM [N m/A]: torque per q-axis ampere with i_d = 0 (eq. ``dq0voltage``)."""
        return 1.5 * self.pole_pairs * self.flux_linkage


@dataclass(frozen=True)
class ScrewColumn:
    """The screw of an EMLA as a column under its push force (buckling, :mod:`hiab_sim.structure.buckling`).

    Attributes:
        root_diameter: Thread root (minor) diameter d_r of the screw shaft [m]; the section
            A = pi d_r^2 / 4, I = pi d_r^4 / 64 of the ball-screw catalogues' buckling formula.
        elastic_modulus: Young's modulus E of the screw steel [Pa].
        yield_strength: Compressive yield strength sigma_y of the screw core [Pa] (Johnson parabola).
        end_fixity_factor: The catalogues' mounting factor N of P = N pi^2 E I / l^2 [-]: 1 pinned-
            pinned, 2 fixed-supported, 4 fixed-fixed, 0.25 fixed-free (effective length l / sqrt(N)).
        retracted_length: Column length at zero stroke [m] of an actuator that is not in a closed
            chain (a direct actuator); None for a chain's actuator, whose column is its pin-to-pin
            length x0 + x.
        label: Prefix used in error messages.

    """

    root_diameter: float
    elastic_modulus: float
    yield_strength: float
    end_fixity_factor: float
    retracted_length: float | None = None
    label: str = "screw"

    def __post_init__(self) -> None:
        check_fields(self, positive={"root_diameter": "m", "elastic_modulus": "Pa", "yield_strength": "Pa"})
        if not (math.isfinite(self.yield_strength) and self.yield_strength < self.elastic_modulus):
            raise InvalidInputError(
                f"{self.label}.yield_strength", self.yield_strength, "must be < elastic_modulus", "Pa"
            )
        check_range(f"{self.label}.end_fixity_factor", self.end_fixity_factor, 0.0, 4.0, low_open=True)
        if self.retracted_length is not None:
            check_positive(f"{self.label}.retracted_length", self.retracted_length, "m")


@dataclass(frozen=True)
class EmlaParams:
    """One electromechanical linear actuator: PMSM, gearbox, screw (eqs. ``torque_torque``, ``torque_force``).

    Attributes:
        name: Actuator name (``lift``, ``tilt`` or ``telescope`` for the XS 031), used in messages.
        motor: The PMSM.
        gear_ratio: Gearbox ratio G [-] (motor turns per screw turn), > 1 (a reduction).
        screw_lead: Screw lead rho [m per screw revolution], > 0.
        screw_moving_mass: Screw moving mass M_sm [kg], >= 0.
        viscous_friction: Screw viscous friction b_f [N s/m], >= 0.
        hydraulic_push_force: Push force of the hydraulic cylinder this EMLA replaces [N], or None.
        hydraulic_pull_force: Pull force of that cylinder [N], or None.
        losses: Optional drive losses (:mod:`hiab_sim.emla.losses`); the default is all off.
        thermal: Continuous torque and winding thermal model (:mod:`hiab_sim.emla.thermal`), or None.
        winding: Temperature dependence of R_s (:mod:`hiab_sim.emla.electrothermal`), or None
            (R_s constant, the seed paper's model).
        brake: The holding brake on the motor shaft (:mod:`hiab_sim.emla.brake`), or None.
        screw: The screw as a column (buckling), or None when the file gives no ``screw`` section.
        stiffness: Drive-train stiffness data (:mod:`hiab_sim.emla.drive_stiffness`), or None without it.
        provenance: (parameter key, source label) pairs, e.g.
            ``("pmsm.peak_torque", "estimate: 3 x rated torque ...")``.

    """

    name: str
    motor: PmsmParams
    gear_ratio: float
    screw_lead: float
    screw_moving_mass: float
    viscous_friction: float
    hydraulic_push_force: float | None = None
    hydraulic_pull_force: float | None = None
    losses: DriveLosses = field(default_factory=DriveLosses)
    thermal: ThermalParams | None = None
    winding: WindingResistance | None = None
    brake: HoldingBrake | None = None
    provenance: tuple[tuple[str, str], ...] = ()
    screw: ScrewColumn | None = None
    stiffness: DriveStiffness | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.gear_ratio) and self.gear_ratio > 1.0):
            raise InvalidInputError(f"{self.name}.gear_ratio", self.gear_ratio, "must be finite and > 1 (a reduction)")
        check_fields(
            self,
            positive={"screw_lead": "m"},
            non_negative={"screw_moving_mass": "kg", "viscous_friction": "N s/m"},
            where=self.name,
        )
        for key in ("hydraulic_push_force", "hydraulic_pull_force"):
            value = getattr(self, key)
            if value is not None:
                check_positive(f"{self.name}.{key}", value, "N")

    @property
    def transmission_ratio(self) -> float:
        """Transmission ratio k = 2 pi G / rho [rad/m]: motor angle per rod metre (eq. ``torque_force``)."""
        return 2.0 * math.pi * self.gear_ratio / self.screw_lead

    def source_of(self, key: str) -> str:
        """Return the provenance label of a parameter key such as ``"gear_ratio"`` or ``"pmsm.Ld"``."""
        return dict(self.provenance).get(key, "unspecified")
