"""What the controller measures: the motor-shaft encoder with its resolution, a delay, and current-sensor errors.

Encoder: the motor angle theta_m = k x_m is quantised to Delta = 2 pi / N (N counts per
revolution), theta_q = Delta round(theta_m / Delta), and reported at the rod as x_q = theta_q / k; the
rate is the backward difference (x_q - x_q,prev) / h over the physics step. Both reach the
controller ``delay_steps`` = round(delay / h) physics steps late. Off, the controller sees the exact
motor-side stroke and rate (the rod's when the drive train is rigid).

Current sensors: the q-axis measurement reads i_q + offset + n, n white with the rms of one sample
at the inverter rate. A current loop regulates the measurement, so the drive carries
i* - offset - n; a continuous loop sees n averaged over the physics step, rms sigma / sqrt(f_s h).
"""

from __future__ import annotations

import collections
import math

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.env.plant.config import Sensors


class MotionSensor:
    """Encoder and delay of n drives (module docstring); ``None`` settings measure exactly."""

    def __init__(self, sensors: Sensors | None, ratio: Array, h: float) -> None:
        self.enabled = sensors is not None and sensors.enabled
        self.ratio = np.asarray(ratio, dtype=float)
        self.h = h
        counts = sensors.encoder_counts_per_rev if sensors is not None else 1
        self.resolution = 2.0 * math.pi / counts
        self.delay_steps = round(sensors.delay_s / h) if sensors is not None and self.enabled else 0
        self.buffer: collections.deque[tuple[Array, Array]] = collections.deque(maxlen=self.delay_steps + 1)
        self.previous = np.zeros_like(self.ratio)

    def reset(self, position: Array, velocity: Array) -> None:
        """Fill the delay line with a state at rest in the past (position, velocity held)."""
        self.buffer.clear()
        quantised = self.quantise(np.asarray(position, dtype=float))
        self.previous = quantised
        sample = (quantised, np.asarray(velocity, dtype=float).copy()) if self.enabled else (position, velocity)
        for _ in range(self.delay_steps + 1):
            self.buffer.append((np.array(sample[0]), np.array(sample[1])))

    def quantise(self, position: Array) -> Array:
        """x_q = Delta round(k x / Delta) / k [m] (exact when the sensors are off)."""
        if not self.enabled:
            return position
        return self.resolution * np.round(self.ratio * position / self.resolution) / self.ratio

    def push(self, position: Array, velocity: Array) -> None:
        """Record the true motor-side stroke [m] and rate [m/s] at the end of a physics step."""
        if not self.enabled:
            self.buffer.append((np.array(position), np.array(velocity)))
            return
        quantised = self.quantise(position)
        self.buffer.append((quantised, (quantised - self.previous) / self.h))
        self.previous = quantised

    def measured(self) -> tuple[Array, Array]:
        """(stroke [m], rate [m/s]) as the controller receives them now."""
        return self.buffer[0]


class CurrentSensorError:
    """Offset and noise of the q-axis current measurement of n drives (module docstring)."""

    def __init__(self, sensors: Sensors | None, n: int, samples_per_step: float) -> None:
        self.enabled = sensors is not None and sensors.enabled
        self.offset = sensors.current_offset_A if sensors is not None and self.enabled else 0.0
        self.noise = sensors.current_noise_rms_A if sensors is not None and self.enabled else 0.0
        self.rng = np.random.default_rng(sensors.seed if sensors is not None else 0)
        self.n = n
        self.step_noise = self.noise / math.sqrt(max(samples_per_step, 1.0))

    def sample(self, size: int | None = None) -> Array:
        """Measurement error offset + n [A]: (n,) per physics step, or (size, n) at the inverter rate."""
        if not self.enabled:
            return np.zeros((self.n,) if size is None else (size, self.n))
        if size is None:
            return self.offset + self.step_noise * self.rng.standard_normal(self.n)
        return self.offset + self.noise * self.rng.standard_normal((size, self.n))
