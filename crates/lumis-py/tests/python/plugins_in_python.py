"""Plugins written in Python, shared by the tests and the book: a
Lambertian BSDF, a point light and an independent sampler."""

import math
import random


class Lambert:
    """Lambertian reflection, cosine-weighted sampling."""

    flags = "diffuse|reflection"

    def __init__(self, reflectance):
        self.albedo = reflectance

    def f(self, wo, wi):
        if wo[2] <= 0 or wi[2] <= 0:
            return (0.0, 0.0, 0.0)
        return tuple(a / math.pi for a in self.albedo)

    def pdf(self, wo, wi):
        return wi[2] / math.pi if wo[2] > 0 and wi[2] > 0 else 0.0

    def sample_f(self, wo, u1, u2):
        if wo[2] <= 0:
            return None
        # Malley's method: a uniform disk point lifted to the hemisphere.
        r, phi = math.sqrt(u2[0]), 2 * math.pi * u2[1]
        wi = (r * math.cos(phi), r * math.sin(phi), math.sqrt(max(0.0, 1 - u2[0])))
        pdf = self.pdf(wo, wi)
        return (self.f(wo, wi), wi, pdf) if pdf > 0 else None


class PointLight:
    """An isotropic point light."""

    kind = "delta_position"

    def __init__(self, position, intensity):
        self.position, self.intensity = position, intensity

    def sample_li(self, p, n, u):
        d = [a - b for a, b in zip(self.position, p)]
        d2 = sum(c * c for c in d)
        if d2 == 0:
            return None
        wi = tuple(c / math.sqrt(d2) for c in d)
        return (tuple(i / d2 for i in self.intensity), wi, 1.0, self.position)

    def pdf_li(self, p, n, wi):
        return 0.0

    def l(self, p, n, uv, w):
        return (0.0, 0.0, 0.0)

    def power(self):
        return tuple(4 * math.pi * i for i in self.intensity)


class Independent:
    """Independent uniform numbers, seeded by pixel, sample and seed."""

    def __init__(self, spp):
        self.spp = spp
        self.random = random.Random()

    def start_pixel_sample(self, pixel, index, seed):
        self.random.seed(hash((pixel, index, seed)))

    def get_1d(self):
        return self.random.random()

    def get_2d(self):
        return (self.random.random(), self.random.random())

    def get_pixel_2d(self):
        return self.get_2d()
