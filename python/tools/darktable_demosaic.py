"""darktable's two default Bayer demosaics, PPG (default until 3.4) and RCD (default from 3.6), written in numpy
from the algorithms' descriptions for an RGGB mosaic normalised to [0, 1].

Only what shapes the noise of the output is kept: the direction choices, the clamps, the ratio-corrected
estimates and the colour-difference steps. Tiling, the border fill and OpenCL are left out, so the outermost
``BORDER`` pixels of the result are not darktable's and callers crop them.
"""
import numpy as np

#: Pixels at each edge that the interior steps do not reach (RCD reads 4 pixels out and refines over one more).
BORDER = 10
_EPS = 1e-5
_EPS_SQ = 1e-10


def _shifted(padded, pad, shape):
    rows, cols = shape

    def at(dy, dx):
        return padded[pad + dy:pad + dy + rows, pad + dx:pad + dx + cols]

    return at


def _sites(shape):
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
    red = (rows % 2 == 0) & (cols % 2 == 0)
    blue = (rows % 2 == 1) & (cols % 2 == 1)
    return red, blue, ~(red | blue)


def _ppg_green(mosaic):
    """Green at red and blue sites: the direction of the smaller gradient, Hamilton-Adams' guess clamped to the two
    neighbours along it."""
    at = _shifted(np.pad(mosaic, 3, mode="reflect"), 3, mosaic.shape)
    c = at(0, 0)
    xm, xp, xm2, xp2, xm3, xp3 = at(0, -1), at(0, 1), at(0, -2), at(0, 2), at(0, -3), at(0, 3)
    ym, yp, ym2, yp2, ym3, yp3 = at(-1, 0), at(1, 0), at(-2, 0), at(2, 0), at(-3, 0), at(3, 0)
    grad_x = (abs(xm2 - c) + abs(xp2 - c) + abs(xm - xp)) * 3 + (abs(xp3 - xp) + abs(xm3 - xm)) * 2
    grad_y = (abs(ym2 - c) + abs(yp2 - c) + abs(ym - yp)) * 3 + (abs(yp3 - yp) + abs(ym3 - ym)) * 2
    guess_x = np.clip(((xm + c + xp) * 2 - xp2 - xm2) / 4, np.minimum(xm, xp), np.maximum(xm, xp))
    guess_y = np.clip(((ym + c + yp) * 2 - yp2 - ym2) / 4, np.minimum(ym, yp), np.maximum(ym, yp))
    interpolated = np.where(grad_x > grad_y, guess_y, guess_x)
    red, blue, _ = _sites(mosaic.shape)
    green = mosaic.copy()
    green[red | blue] = interpolated[red | blue]
    return green


def ppg_green(mosaic):
    """PPG's green plane alone (no clamp at zero, so that it can run on zero-mean noise)."""
    return _ppg_green(mosaic)


def _colour_differences(rgb, red, blue, green_sites):
    """The second pass PPG shares with RCD's border: red and blue at green sites from the two neighbours that
    carry them, the other colour at red and blue sites along the diagonal of smaller gradient, each as the
    green there plus the neighbours' colour difference."""
    pad = 1
    at = [_shifted(np.pad(rgb[..., k], pad, mode="reflect"), pad, rgb.shape[:2]) for k in range(3)]
    g = rgb[..., 1]
    out = rgb.copy()
    rows = np.arange(rgb.shape[0])[:, None] % 2 == 0
    rows = np.broadcast_to(rows, rgb.shape[:2])
    vertical = {k: (at[k](-1, 0) + at[k](1, 0) + 2 * g - at[1](-1, 0) - at[1](1, 0)) / 2 for k in (0, 2)}
    horizontal = {k: (at[k](0, -1) + at[k](0, 1) + 2 * g - at[1](0, -1) - at[1](0, 1)) / 2 for k in (0, 2)}
    # A green site in a red row has red left and right, blue above and below; in a blue row the reverse.
    in_red_row = green_sites & rows
    in_blue_row = green_sites & ~rows
    out[..., 0] = np.where(in_red_row, horizontal[0], np.where(in_blue_row, vertical[0], out[..., 0]))
    out[..., 2] = np.where(in_red_row, vertical[2], np.where(in_blue_row, horizontal[2], out[..., 2]))
    for k, sites in ((2, red), (0, blue)):
        diff1 = abs(at[k](-1, -1) - at[k](1, 1)) + abs(at[1](-1, -1) - g) + abs(at[1](1, 1) - g)
        guess1 = at[k](-1, -1) + at[k](1, 1) + 2 * g - at[1](-1, -1) - at[1](1, 1)
        diff2 = abs(at[k](-1, 1) - at[k](1, -1)) + abs(at[1](-1, 1) - g) + abs(at[1](1, -1) - g)
        guess2 = at[k](-1, 1) + at[k](1, -1) + 2 * g - at[1](-1, 1) - at[1](1, -1)
        value = np.where(diff1 > diff2, guess2 / 2, np.where(diff1 < diff2, guess1 / 2, (guess1 + guess2) / 4))
        out[..., k] = np.where(sites, value, out[..., k])
    return out


def ppg(mosaic):
    """darktable's PPG on an RGGB mosaic: clamped at zero on reading, green, then colour differences, each pass
    clamped at zero as darktable writes it. Returns rows x cols x 3."""
    clamped = np.maximum(mosaic, 0)
    red, blue, green_sites = _sites(mosaic.shape)
    rgb = np.zeros(mosaic.shape + (3,))
    rgb[..., 0] = np.where(red, clamped, 0)
    rgb[..., 2] = np.where(blue, clamped, 0)
    rgb[..., 1] = np.maximum(_ppg_green(clamped), 0)
    return np.maximum(_colour_differences(rgb, red, blue, green_sites), 0)


def _hpf(at, dy, dx):
    """RCD's squared colour-difference high pass along one direction (a seven-tap filter through both colours)."""
    return ((at(-3 * dy, -3 * dx) - at(-dy, -dx) - at(dy, dx) + at(3 * dy, 3 * dx))
            - 3 * (at(-2 * dy, -2 * dx) + at(2 * dy, 2 * dx)) + 6 * at(0, 0)) ** 2


def _compact_reader(shape):
    """RCD keeps its diagonal high passes and P/Q strengths at every other column, indexed by (flat index) / 2 of
    the pixel asked for. This reads such a store the way its index arithmetic does: the pixel (dy, dx) away,
    then ``further`` elements on (RCD's '+ 1' after its division)."""
    rows, cols = shape
    flat = np.arange(rows * cols).reshape(shape)

    def read(store, dy, dx, further=0):
        index = np.clip((flat + dy * cols + dx) // 2 + further, 0, store.size - 1)
        return store.ravel()[index]

    return read


def _interpolate(weight, a, b):
    return weight * (a - b) + b


def _refined(direction, neighbours):
    """RCD's refinement: the centre's direction strength, or its diagonal neighbours' mean when that is surer."""
    return np.where(abs(0.5 - direction) < abs(0.5 - neighbours), neighbours, direction)


def rcd(mosaic):
    """darktable's RCD (ratio corrected demosaicing) on an RGGB mosaic. Returns rows x cols x 3; the outer
    ``BORDER`` pixels are not darktable's."""
    shape = mosaic.shape
    pad = 8
    cfa = np.maximum(mosaic, 0)
    at = _shifted(np.pad(cfa, pad, mode="reflect"), pad, shape)
    red, blue, green_sites = _sites(shape)
    colour_sites = red | blue

    # Step 1: vertical against horizontal, from the high passes of the three rows or columns around.
    hv, hh = _hpf(at, 1, 0), _hpf(at, 0, 1)
    at_v = _shifted(np.pad(hv, 1, mode="reflect"), 1, shape)
    at_h = _shifted(np.pad(hh, 1, mode="reflect"), 1, shape)
    v_stat = np.maximum(_EPS_SQ, at_v(-1, 0) + hv + at_v(1, 0))
    h_stat = np.maximum(_EPS_SQ, at_h(0, -1) + hh + at_h(0, 1))
    vh_dir = v_stat / (v_stat + h_stat)
    at_vh = _shifted(np.pad(vh_dir, 1, mode="reflect"), 1, shape)
    vh_disc = _refined(vh_dir, 0.25 * (at_vh(-1, -1) + at_vh(-1, 1) + at_vh(1, -1) + at_vh(1, 1)))

    # Step 2: a low pass through all colours, at red and blue sites.
    lpf = at(0, 0) + 0.5 * (at(-1, 0) + at(1, 0) + at(0, -1) + at(0, 1)) + 0.25 * (
        at(-1, -1) + at(-1, 1) + at(1, -1) + at(1, 1))
    at_lpf = _shifted(np.pad(lpf, 2, mode="reflect"), 2, shape)

    # Step 3: green at red and blue sites, each neighbour's green corrected by the ratio of the low passes.
    def gradient(dy, dx):
        return _EPS + abs(at(-dy, -dx) - at(dy, dx)) + abs(at(0, 0) - at(2 * dy, 2 * dx)) + abs(
            at(dy, dx) - at(3 * dy, 3 * dx)) + abs(at(2 * dy, 2 * dx) - at(4 * dy, 4 * dx))

    def estimate(dy, dx):
        return at(dy, dx) * (lpf + lpf) / (_EPS + lpf + at_lpf(2 * dy, 2 * dx))

    n_grad, s_grad, w_grad, e_grad = gradient(-1, 0), gradient(1, 0), gradient(0, -1), gradient(0, 1)
    v_est = (s_grad * estimate(-1, 0) + n_grad * estimate(1, 0)) / (n_grad + s_grad)
    h_est = (w_grad * estimate(0, 1) + e_grad * estimate(0, -1)) / (e_grad + w_grad)
    green = np.where(colour_sites, _interpolate(vh_disc, h_est, v_est), cfa)

    # Step 4: the other colour at red and blue sites along the surer diagonal.
    read = _compact_reader(shape)
    p_full, q_full = _hpf(at, 1, 1), _hpf(at, 1, -1)
    p_store = p_full[:, 1::2].copy()  # computed at odd columns, stored at (flat index) / 2
    q_store = q_full[:, 1::2].copy()
    cols = shape[1]
    p_stat = np.maximum(_EPS_SQ, read(p_store, -1, -1) + read(p_store, 0, 0) + read(p_store, 1, -1, 1))
    q_stat = np.maximum(_EPS_SQ, read(q_store, -1, -1, 1) + read(q_store, 0, 0) + read(q_store, 1, -1))
    pq_dir = np.zeros(shape)
    pq_dir[colour_sites] = (p_stat / (p_stat + q_stat))[colour_sites]
    pq_store = np.zeros((shape[0], cols // 2))
    flat = np.arange(shape[0] * cols).reshape(shape)
    pq_store.ravel()[flat[colour_sites] // 2] = pq_dir[colour_sites]
    pq_neighbours = 0.25 * (read(pq_store, -1, -1) + read(pq_store, -1, -1, 1) + read(pq_store, 1, -1)
                            + read(pq_store, 1, -1, 1))
    pq_disc = _refined(pq_dir, pq_neighbours)

    rgb = np.zeros(shape + (3,))
    rgb[..., 0] = np.where(red, cfa, 0)
    rgb[..., 2] = np.where(blue, cfa, 0)
    rgb[..., 1] = green
    at_g = _shifted(np.pad(green, 4, mode="reflect"), 4, shape)
    for k, sites in ((2, red), (0, blue)):
        at_c = _shifted(np.pad(rgb[..., k], 4, mode="reflect"), 4, shape)
        nw_grad = _EPS + abs(at_c(-1, -1) - at_c(1, 1)) + abs(at_c(-1, -1) - at_c(-3, -3)) + abs(green - at_g(-2, -2))
        ne_grad = _EPS + abs(at_c(-1, 1) - at_c(1, -1)) + abs(at_c(-1, 1) - at_c(-3, 3)) + abs(green - at_g(-2, 2))
        sw_grad = _EPS + abs(at_c(-1, 1) - at_c(1, -1)) + abs(at_c(1, -1) - at_c(3, -3)) + abs(green - at_g(2, -2))
        se_grad = _EPS + abs(at_c(-1, -1) - at_c(1, 1)) + abs(at_c(1, 1) - at_c(3, 3)) + abs(green - at_g(2, 2))
        nw, ne = at_c(-1, -1) - at_g(-1, -1), at_c(-1, 1) - at_g(-1, 1)
        sw, se = at_c(1, -1) - at_g(1, -1), at_c(1, 1) - at_g(1, 1)
        p_est = (nw_grad * se + se_grad * nw) / (nw_grad + se_grad)
        q_est = (ne_grad * sw + sw_grad * ne) / (ne_grad + sw_grad)
        rgb[..., k] = np.where(sites, green + _interpolate(pq_disc, q_est, p_est), rgb[..., k])

    # Step 5: red and blue at green sites, along the direction step 1 chose.
    def green_gradient(dy, dx):
        return _EPS + abs(green - at_g(2 * dy, 2 * dx))

    n1, s1, w1, e1 = green_gradient(-1, 0), green_gradient(1, 0), green_gradient(0, -1), green_gradient(0, 1)
    for k in (0, 2):
        at_c = _shifted(np.pad(rgb[..., k], 4, mode="reflect"), 4, shape)
        sn, ew = abs(at_c(-1, 0) - at_c(1, 0)), abs(at_c(0, -1) - at_c(0, 1))
        n_g = n1 + sn + abs(at_c(-1, 0) - at_c(-3, 0))
        s_g = s1 + sn + abs(at_c(1, 0) - at_c(3, 0))
        w_g = w1 + ew + abs(at_c(0, -1) - at_c(0, -3))
        e_g = e1 + ew + abs(at_c(0, 1) - at_c(0, 3))
        n_e, s_e = at_c(-1, 0) - at_g(-1, 0), at_c(1, 0) - at_g(1, 0)
        w_e, e_e = at_c(0, -1) - at_g(0, -1), at_c(0, 1) - at_g(0, 1)
        v = (n_g * s_e + s_g * n_e) / (n_g + s_g)
        h = (e_g * w_e + w_g * e_e) / (e_g + w_g)
        rgb[..., k] = np.where(green_sites, green + _interpolate(vh_disc, h, v), rgb[..., k])
    return np.maximum(rgb, 0)

