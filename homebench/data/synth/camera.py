"""The camera of generated worlds: scene radiance in, 8-bit grey images out.

Every generated image passes through this one model. A pose is **one capture**: its exposure is
decided once, and the raw catadioptric image and the unfolded panorama are two read-outs of it
(each with its own sensor noise). The stages, in order:

1. **Optics** (:meth:`Camera.optics`): the mirror and lens blur the view with a Gaussian
   point-spread function of ``blur_deg`` (standard deviation, degrees of view angle, isotropic
   in the panorama's azimuth and elevation), and the irradiance falls off towards the rim of
   the mirror image: relative irradiance ``1 - falloff * (r / r_outer)**2`` at raw-image radius
   ``r`` (the leading term of the cos^4 law), applied per elevation so that both image kinds
   see the same fall-off.
2. **Exposure** (:meth:`Camera.meter`): an exposure time ``t`` and an analog gain ``g``. With
   ``exposure: auto`` the camera meters like a real auto-exposure loop at convergence: it
   chooses ``t`` so that the mean of the *clipped* linear signal over the metering region equals
   ``target`` (18 % grey by default); a saturated window therefore pulls the exposure down only
   as much as its clipped area weighs. ``t`` is limited to ``exposure_time_range``; past the
   longest time the gain rises up to ``max_gain`` (and with it the noise), as in dim light.
   The metering region is the whole mirror image (``metering: annulus``, each direction
   weighted by the raw-image area it covers, i.e. by its radius) or the band of
   ``+-metering_band_deg`` around the horizon (``metering: horizon``). Metering uses the
   noise-free signal (a real loop averages over many frames). ``exposure: fixed`` uses
   ``exposure_time`` and gain 1: a brighter scene then gives a brighter image.
3. **Sensor** (:meth:`Camera.read_out`): photo-electrons ``e = full_well * L * t / 255`` for
   scene radiance ``L`` (the lighting model's units: a white surface under the original room's
   light is about 100-300; 255 fills the well at ``t = 1``), shot noise (Poisson, in its
   Gaussian approximation with variance ``e``) plus read noise (``read_noise`` electrons rms),
   clipped at the full well; then the gain, and the converter's clipping at full scale.
4. **Response**: the sRGB transfer curve (linear toe, then a 1/2.4 power; ``response: srgb``)
   or none (``response: linear``), and rounding to 8 bits.

Noise is seeded per read-out (a seed from the caller), never by the scene, so two renders of
one pose with one seed are bit-identical; ``noise: false`` reads out without it (an ideal
sensor). Pixels outside the mirror's annulus of a raw image see no light and are black.

The **mount** comes before all of it: a real robot's camera axis is never quite vertical.
``tilt_deg`` > 0 tilts the axis of each capture by a seeded random angle up to ``tilt_deg``
towards a random direction (:mod:`homebench.data.synth.tilt`; the world applies it to the
scene's radiance before the optics, so the blur, the fall-off and the metering act in the
tilted camera's frame, as they would).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import cv2
import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from homebench.geometry import CatadioptricGeometry, PanoramaGeometry

Float32 = NDArray[np.float32]
FloatArray = NDArray[np.float64]

#: Scene radiance that fills the sensor's well at exposure time 1 (the lighting model's units).
SATURATION_RADIANCE = 255.0
#: Bisection steps of the auto-exposure search (log2 of the time range / 2**-steps precision).
_METERING_STEPS = 48
#: The metering image is the panorama area-averaged by this factor in both directions.
_METERING_DOWNSAMPLE = 4


class CameraSpec(BaseModel):
    """Parameters of the generated worlds' camera (see the module docstring for each stage)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    blur_deg: float = Field(0.35, ge=0, le=10)  # optics' Gaussian blur, sd in degrees of view
    # irradiance fall-off at the mirror's rim: 1 - falloff x (r / r_outer)^2
    falloff: float = Field(0.3, ge=0, lt=1)
    # auto: metered to target; fixed: exposure_time at gain 1 (brighter scene, brighter image)
    exposure: Literal["auto", "fixed"] = "auto"
    # auto: the mean clipped linear signal over the metering region (0.18: 18 % grey)
    target: float = Field(0.18, gt=0, lt=1)
    # auto: the metering region, the whole mirror image or a band around the horizon
    metering: Literal["annulus", "horizon"] = "annulus"
    metering_band_deg: float = Field(20.0, gt=0, le=90)  # horizon metering: +- degrees
    # auto: (shortest, longest) exposure time (1 = the time at which radiance 255 fills the well)
    exposure_time_range: tuple[float, float] = (1.0 / 256.0, 4.0)
    exposure_time: float = Field(0.6, gt=0)  # fixed: the exposure time
    max_gain: float = Field(16.0, ge=1)  # auto: the most analog gain past the longest time
    full_well: float = Field(8000.0, gt=0)  # sensor full-well capacity, electrons
    read_noise: float = Field(6.0, ge=0)  # sensor read noise, electrons rms
    noise: bool = True  # shot and read noise (false: an ideal sensor)
    response: Literal["srgb", "linear"] = "srgb"  # the transfer curve before 8-bit rounding
    # the most a capture's camera axis tilts from vertical (seeded per capture), degrees
    tilt_deg: float = Field(0.0, ge=0, le=20)

    @model_validator(mode="after")
    def _ordered_range(self) -> CameraSpec:
        low, high = self.exposure_time_range
        if not 0 < low <= high:
            raise ValueError("exposure_time_range must be (shortest, longest) with 0 < shortest")
        return self


@dataclass(frozen=True)
class Exposure:
    """One capture's exposure: time ``t`` (1 = the reference time) and analog ``gain``."""

    time: float
    gain: float

    @property
    def scale(self) -> float:
        """Linear full-scale fraction per unit of scene radiance, noise-free: ``t g / 255``."""
        return self.time * self.gain / SATURATION_RADIANCE


def srgb_encode(linear: Float32) -> Float32:
    """The sRGB transfer curve on linear values in [0, 1] (any shape), float32 in [0, 1]."""
    x = np.asarray(linear, np.float32)
    high = np.float32(1.055) * np.power(np.maximum(x, np.float32(0.0031308)), np.float32(1 / 2.4))
    return np.where(x <= np.float32(0.0031308), np.float32(12.92) * x, high - np.float32(0.055))


class Camera:
    """The camera for one cast-panorama geometry and one raw geometry (see the module docstring).

    ``panorama`` is the geometry of the supersampled cast panorama the optics and the metering
    act on; ``raw`` the mirror model that decides the fall-off and the metering weights.
    """

    def __init__(self, spec: CameraSpec, panorama: PanoramaGeometry, raw: CatadioptricGeometry):
        self.spec, self.panorama, self.raw = spec, panorama, raw
        elevation = panorama.row_to_elevation(np.arange(panorama.height))
        radius = raw.elevation_to_radius(elevation)
        falloff = 1.0 - spec.falloff * (radius / raw.outer_radius) ** 2
        self._falloff = falloff.astype(np.float32)[:, None]  # (height, 1)
        self._blur_px = math.radians(spec.blur_deg) / panorama.row_step
        self._metering_weights = self._weights(elevation, radius)

    def _weights(self, elevation: FloatArray, radius: FloatArray) -> FloatArray:
        """Metering weight of every metering-image row, normalised to sum 1 (shape (rows, 1))."""
        low, high = min(self.raw.elevations), max(self.raw.elevations)
        inside = (elevation >= low) & (elevation <= high)
        if self.spec.metering == "horizon":
            band = math.radians(self.spec.metering_band_deg)
            weights = (inside & (np.abs(elevation) <= band)).astype(np.float64)
        else:
            weights = np.where(inside, radius, 0.0)  # raw pixels per panorama pixel ~ radius
        k = _METERING_DOWNSAMPLE
        rows = len(weights) // k
        weights = weights[: rows * k].reshape(rows, k).mean(axis=1)
        if weights.sum() <= 0:
            raise ValueError("the metering region holds no part of the mirror's view")
        return (weights / weights.sum())[:, None]

    def optics(self, radiance: Float32) -> Float32:
        """Blur and fall-off of a cast panorama's radiance (height, width), float32.

        Azimuth wraps round (the blur crosses the seam); rows replicate at the top and bottom.
        """
        out = radiance * self._falloff
        if self._blur_px <= 0:
            return out.astype(np.float32)
        pad = int(math.ceil(4 * self._blur_px))
        wrapped = np.concatenate([out[:, -pad:], out, out[:, :pad]], axis=1)
        blurred = cv2.GaussianBlur(wrapped, (0, 0), self._blur_px, borderType=cv2.BORDER_REPLICATE)
        return np.ascontiguousarray(blurred[:, pad:-pad], dtype=np.float32)

    def _metering_samples(self, radiance: Float32) -> tuple[FloatArray, FloatArray]:
        """The metering image (the panorama area-averaged, (rows, cols)) and its weights
        (rows, 1), which sum to 1 over the image."""
        k = _METERING_DOWNSAMPLE
        h, w = radiance.shape
        small = cv2.resize(
            radiance[: h // k * k, : w // k * k], (w // k, h // k), interpolation=cv2.INTER_AREA
        ).astype(np.float64)
        return small, self._metering_weights / small.shape[1]

    @staticmethod
    def _level(samples: FloatArray, weights: FloatArray, scale: float) -> float:
        return float(np.sum(np.minimum(samples * scale, 1.0) * weights))

    def metered_level(self, radiance: Float32, exposure: Exposure) -> float:
        """The weighted mean of the clipped linear signal over the metering region (0..1)."""
        return self._level(*self._metering_samples(radiance), exposure.scale)

    def meter(self, radiance: Float32) -> Exposure:
        """The exposure of a capture of ``radiance`` (the optics' output, (height, width))."""
        spec = self.spec
        if spec.exposure == "fixed":
            return Exposure(spec.exposure_time, 1.0)
        samples, weights = self._metering_samples(radiance)

        def metered(product: float) -> float:
            return self._level(samples, weights, product / SATURATION_RADIANCE)

        shortest, longest = spec.exposure_time_range
        most = longest * spec.max_gain  # the largest time x gain
        if metered(shortest) >= spec.target:
            product = shortest
        elif metered(most) <= spec.target:
            product = most
        else:  # bisection on log(t g): metered() is monotone in it
            lo, hi = math.log(shortest), math.log(most)
            for _ in range(_METERING_STEPS):
                mid = 0.5 * (lo + hi)
                if metered(math.exp(mid)) < spec.target:
                    lo = mid
                else:
                    hi = mid
            product = math.exp(0.5 * (lo + hi))
        time = min(product, longest)
        return Exposure(time, product / time)

    def read_out(
        self,
        radiance: Float32,
        exposure: Exposure,
        noise_seed: int | None,
        stream: int,
        light_mask: NDArray[np.bool_] | None = None,
    ) -> NDArray[np.uint8]:
        """One 8-bit read-out of an image of scene radiance (any (h, w), after the optics).

        ``noise_seed`` None (or the spec's ``noise: false``) reads out without noise; else
        the noise comes from ``default_rng([noise_seed, stream])``. ``light_mask`` (h, w):
        where the sensor sees the scene (False: black, e.g. outside a raw image's annulus).
        """
        spec = self.spec
        well = np.float32(spec.full_well)
        electrons = radiance * np.float32(spec.full_well * exposure.time / SATURATION_RADIANCE)
        electrons = np.maximum(electrons, np.float32(0.0))
        if noise_seed is not None and spec.noise:
            rng = np.random.default_rng([noise_seed, stream])
            sigma = np.sqrt(electrons + np.float32(spec.read_noise**2))
            electrons = electrons + rng.standard_normal(electrons.shape, dtype=np.float32) * sigma
        linear = np.clip(electrons, 0.0, well) * np.float32(exposure.gain) / well
        linear = np.minimum(linear, np.float32(1.0))
        encoded = srgb_encode(linear) if spec.response == "srgb" else linear
        out = np.rint(encoded * np.float32(255.0)).astype(np.uint8)
        if light_mask is not None:
            out[~light_mask] = 0
        return out
