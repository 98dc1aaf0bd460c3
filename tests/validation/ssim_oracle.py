#!/usr/bin/python3
"""The scikit-image oracle of the metric tests (DESIGN 6.2).

Usage: /usr/bin/python3 tests/validation/ssim_oracle.py DIR

DIR holds image pairs NAME.a.png and NAME.b.png (8-bit RGB). For each pair this prints, as one
JSON object on stdout, scikit-image's MSE, PSNR (data_range 255) and SSIM with the settings of
Wang et al. 2004 (Gaussian window sigma 1.5, population covariance, data_range 255, per channel):

  {"skimage": "0.19.3", "pairs": {"NAME": {"mse": ..., "psnr": ... | "inf", "ssim": ... | null,
   "ssim_error": null | "message"}, ...}}

SSIM is null with the error message when scikit-image refuses the pair (images under 11x11).
Exit status 5 with a message on stderr when scikit-image cannot be imported.
"""
import json
import math
import os
import sys
import warnings


def main():
    if len(sys.argv) != 2:
        print("usage: ssim_oracle.py DIR", file=sys.stderr)
        return 3
    try:
        import numpy as np
        import skimage
        from PIL import Image
        from skimage.metrics import mean_squared_error, peak_signal_noise_ratio, structural_similarity
    except ImportError as e:
        print(f"cannot import scikit-image ({e}); install it with `ci/install-deps.sh skimage`", file=sys.stderr)
        return 5

    folder = sys.argv[1]
    names = sorted(f[: -len(".a.png")] for f in os.listdir(folder) if f.endswith(".a.png"))
    pairs = {}
    for name in names:
        a = np.asarray(Image.open(os.path.join(folder, name + ".a.png")).convert("RGB"), dtype=np.uint8)
        b = np.asarray(Image.open(os.path.join(folder, name + ".b.png")).convert("RGB"), dtype=np.uint8)
        with warnings.catch_warnings():
            # PSNR of identical images divides by zero: infinity is the expected answer.
            warnings.simplefilter("ignore")
            mse = float(mean_squared_error(a, b))
            psnr = float(peak_signal_noise_ratio(a, b, data_range=255))
        record = {"width": int(a.shape[1]), "height": int(a.shape[0]), "mse": mse,
                  "psnr": "inf" if math.isinf(psnr) else psnr, "ssim": None, "ssim_error": None}
        try:
            record["ssim"] = float(structural_similarity(a, b, channel_axis=2, gaussian_weights=True, sigma=1.5,
                                                         use_sample_covariance=False, data_range=255))
        except ValueError as e:
            record["ssim_error"] = str(e)
        pairs[name] = record
    json.dump({"skimage": skimage.__version__, "pairs": pairs}, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
