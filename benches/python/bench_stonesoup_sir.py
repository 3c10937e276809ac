"""Stone Soup's particle filter on the step `cargo bench -p sillage-filter --bench sir` times.

    python benches/python/bench_stonesoup_sir.py [--targets 100] [--particles 500] [--steps 20]

The same SIR step as the Rust bench's "single" case: every target predicted by a constant
velocity model (position and velocity noise variances 1 and 0.25 px² per axis, one frame
per step), weighted by a Gaussian position likelihood of 3 px² per axis, then resampled
multinomially at every step. Each target has its own particle state; the targets are
stepped one after the other (Stone Soup has no batch over targets). Prints the median time
of one step of all targets, to be put beside the criterion median measured in the same
session (run one right after the other: absolute times drift on shared machines).

Stone Soup's constant-velocity model is the continuous white-noise-acceleration one (its
noise is correlated between position and velocity), not sillage's independent noises; the
work per particle is the same (a 4-D Gaussian draw and a linear map).
"""

import argparse
import datetime
import platform
import statistics
import time

import numpy as np
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.transition.linear import (
    CombinedLinearGaussianTransitionModel,
    ConstantVelocity,
)
from stonesoup.predictor.particle import ParticlePredictor
from stonesoup.resampler.particle import MultinomialResampler
from stonesoup.types.detection import Detection
from stonesoup.types.hypothesis import SingleHypothesis
from stonesoup.types.state import ParticleState, StateVectors
from stonesoup.updater.particle import ParticleUpdater


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=100)
    parser.add_argument("--particles", type=int, default=500)
    parser.add_argument("--steps", type=int, default=20)
    args = parser.parse_args()

    rng = np.random.default_rng(7)
    transition = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(1.0), ConstantVelocity(1.0)]
    )
    measurement = LinearGaussian(
        ndim_state=4, mapping=(0, 2), noise_covar=np.diag([3.0, 3.0])
    )
    predictor = ParticlePredictor(transition)
    updater = ParticleUpdater(measurement, resampler=MultinomialResampler())

    start = datetime.datetime(2026, 1, 1)
    n = args.particles
    observations = [
        np.array([[40.0 * (k % 64)], [40.0 * (k // 64)]]) for k in range(args.targets)
    ]
    states = []
    for z in observations:
        vectors = np.zeros((4, n))
        vectors[0] = z[0, 0] + rng.normal(size=n)
        vectors[2] = z[1, 0] + rng.normal(size=n)
        vectors[1] = rng.normal(size=n)
        vectors[3] = rng.normal(size=n)
        states.append(
            ParticleState(
                state_vector=StateVectors(vectors),
                weight=np.full(n, 1.0 / n),
                timestamp=start,
            )
        )

    times = []
    for step in range(1, args.steps + 1):
        when = start + datetime.timedelta(seconds=step)
        began = time.perf_counter()
        for k, z in enumerate(observations):
            prediction = predictor.predict(states[k], timestamp=when)
            detection = Detection(z, timestamp=when, measurement_model=measurement)
            states[k] = updater.update(SingleHypothesis(prediction, detection))
        times.append(time.perf_counter() - began)

    # The first steps warm NumPy's and Stone Soup's caches, as the Rust bench's warm-up does.
    median = statistics.median(times[3:] if len(times) > 6 else times)
    print(
        f"Stone Soup {__import__('stonesoup').__version__}, {platform.processor() or platform.machine()}: "
        f"{args.targets} targets x {n} particles, median step {median * 1e3:.1f} ms "
        f"over {len(times)} steps"
    )


if __name__ == "__main__":
    main()
