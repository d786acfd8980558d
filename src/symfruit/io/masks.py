"""Fruit masks from files: instance label PNGs and COCO-style JSON (polygons and RLE).

A COCO file is read with a size bound (:func:`symfruit.io.text.read_structured`) and nothing it says about
sizes is trusted: an image entry's ``height``/``width`` and an RLE's ``size`` must agree with the image the
masks are for *before* anything of that size is allocated, polygon coordinates must be finite numbers,
and the number of annotations per image and of vertices per polygon are bounded.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from ..core.limits import MAX_COCO_BYTES, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, MAX_INSTANCES, check_image_size, shown
from ..errors import FileFormatError, InputError
from .images import orientation_mismatch, read_labels_oriented
from .text import read_structured

#: Largest COCO annotation file read (bytes) and most annotations of one image that are rasterised (a fruit
#: photo holds a handful): :mod:`symfruit.core.limits`.
MAX_INSTANCES_PER_IMAGE = MAX_INSTANCES
#: Most vertices of one polygon, and most values in one uncompressed RLE.
MAX_POLYGON_POINTS = 100_000
MAX_RLE_RUNS = 10_000_000

__all__ = ["CocoSet", "coco_from_data", "coco_masks", "read_coco", "read_label_png", "read_masks", "rle_decode"]


def read_masks(path: str | Path, shape: tuple[int, int], *, color: tuple[str | Path, int] | None = None) -> np.ndarray:
    """Instance labels ``(h, w)`` int32 (0 background, k fruit k) from a label PNG or COCO JSON.

    ``path`` may be a frame folder (its ``masks.png`` or ``masks.json``) or the file itself. ``color``: the
    colour image the labels are for and the EXIF orientation applied to it on reading (1 for pixels that
    carried none); a label PNG must carry the same (:func:`~symfruit.io.images.orientation_mismatch`), so a
    mirrored or half-turned mask, which the size check alone lets through, is refused by name.
    """
    path = Path(path)
    if path.is_dir():
        path = path / "masks.png" if (path / "masks.png").is_file() else path / "masks.json"
    if path.suffix.lower() == ".png":
        labels = read_label_png(path, color=color)
    elif path.suffix.lower() == ".json":
        labels = coco_masks(path, shape)
    else:
        raise FileFormatError(f"{path}: masks must be a label .png or a COCO .json")
    if labels.shape != tuple(shape):
        raise FileFormatError(f"{path}: masks are {labels.shape[1]}x{labels.shape[0]}, the image {shape[1]}x{shape[0]}")
    return labels


def read_label_png(path: Path, *, color: tuple[str | Path, int] | None = None) -> np.ndarray:
    """Instance labels from a label PNG (:func:`~symfruit.io.images.read_labels`), as displayed; ``color`` as in
    :func:`read_masks`: the colour image they are for and its EXIF orientation, which the PNG must carry too
    (None: not checked)."""
    labels, orientation = read_labels_oriented(path)
    if color is not None:
        orientation_mismatch(color[0], color[1], path, orientation, what="labels")
    return labels


def _check_shape(shape: tuple[int, int], where: str) -> tuple[int, int]:
    w, h = check_image_size(shape[1], shape[0], where, error=FileFormatError)
    return h, w


def annotation_mask(ann: Any, shape: tuple[int, int], where: str) -> np.ndarray:
    """``(h, w)`` bool: one COCO annotation's polygons (filled, edges included) or RLE, for an image of
    ``shape``. An RLE whose ``size`` is not ``shape`` is refused before it is decoded."""
    from PIL import Image, ImageDraw

    h, w = shape
    try:
        seg = ann["segmentation"]
        if isinstance(seg, dict):
            size = seg.get("size")
            if not (isinstance(size, list) and len(size) == 2 and [int(size[0]), int(size[1])] == [h, w]):
                raise FileFormatError(f"{where}: RLE size {size!r} is not the image's {[h, w]}")
            return rle_decode(seg)
        if not isinstance(seg, list):  # was "segmentation is a NoneType" (robust53): JSON's words, not Python's
            kind = "null" if seg is None else f"{shown(seg, 40)}"
            raise TypeError(f"segmentation must be polygons (a list) or an RLE (an object), got {kind}")
        if not seg:  # no outline at all: the fruit would vanish from the labels unsaid (as one without the key)
            raise ValueError("segmentation is an empty list")
        img = Image.new("L", (w, h), 0)
        draw = ImageDraw.Draw(img)
        for poly in seg:
            if not isinstance(poly, list) or len(poly) > 2 * MAX_POLYGON_POINTS:
                raise ValueError("a polygon must be a list of at most 100,000 x, y pairs")
            text = next((v for v in poly if isinstance(v, bool | str | bytes)), None)
            if text is not None:  # numpy reads '5' as 5 and true as 1: a coordinate is a number
                raise ValueError(f"polygon coordinates must be numbers, got {shown(text)}")
            xy = np.asarray(poly, dtype=np.float64)
            if xy.ndim != 1 or not np.isfinite(xy).all():
                raise ValueError("polygon coordinates must be finite numbers")
            if len(xy) % 2:  # one coordinate lost or one too many: which is unknown, so the outline is too
                raise ValueError(f"a polygon has {len(xy)} coordinates, an odd number; it is x, y pairs")
            # far-off vertices are clipped (the drawn mask is the same inside the image)
            xy = np.clip(xy.reshape(-1, 2), -4.0 * max(h, w), 5.0 * max(h, w))
            if len(xy) >= 3:
                draw.polygon([tuple(p) for p in xy.tolist()], fill=1, outline=1)
        return np.asarray(img, dtype=bool)
    except FileFormatError:
        raise
    except (KeyError, TypeError, ValueError, IndexError, OverflowError) as exc:
        raise FileFormatError(f"{where} has no valid segmentation ({exc})") from None


def coco_masks(path: Path, shape: tuple[int, int]) -> np.ndarray:
    """Rasterise COCO annotations (polygons, uncompressed or compressed RLE) into instance labels.

    If the file holds several images, the annotations of the first image are used. Later annotations
    are drawn over earlier ones.
    """
    path = Path(path)
    data = read_structured(path, what="COCO annotation file", max_bytes=MAX_COCO_BYTES)
    anns = data.get("annotations", data) if isinstance(data, dict) else data
    if not isinstance(anns, list):
        raise FileFormatError(f"{path}: expected a COCO 'annotations' list")
    for k, ann in enumerate(anns, 1):
        if not isinstance(ann, dict):  # never dropped quietly: that would read as a frame without fruit
            raise FileFormatError(f"{path}: annotation {k} is a {type(ann).__name__}, not an object")
        if ann.get("iscrowd") not in (None, 0, 1):  # "0" as text is truthy: the fruit would be dropped as a crowd
            raise FileFormatError(f"{path}: annotation {k} has iscrowd {shown(ann.get('iscrowd'))}; it is 0 or 1")
    images = data.get("images") if isinstance(data, dict) else None
    if images is not None:
        if not isinstance(images, list) or not all(isinstance(e, dict) for e in images):
            raise FileFormatError(f"{path}: 'images' must be a list of objects")
        if images:
            first = images[0].get("id")
            anns = [a for a in anns if a.get("image_id", first) == first]
    anns = [a for a in anns if not a.get("iscrowd")]  # crowd regions are no instance (COCO ignores them)
    if len(anns) > MAX_INSTANCES_PER_IMAGE:
        raise FileFormatError(f"{path}: {len(anns)} annotations for one image; at most {MAX_INSTANCES_PER_IMAGE}")
    h, w = _check_shape(shape, str(path))
    if images and ("height" in images[0] or "width" in images[0]):  # polygons drawn at another size: misplaced
        try:
            stated = (int(images[0]["height"]), int(images[0]["width"]))
        except (KeyError, TypeError, ValueError, OverflowError):
            raise FileFormatError(f"{path}: the image's height/width are not whole numbers") from None
        if stated != (h, w):
            raise FileFormatError(f"{path}: its image is {stated[1]}x{stated[0]} but the frame's is {w}x{h}; "
                                  "annotate the frame's own colour image")  # fmt: skip
    idents: dict[int, int] = {}  # label -> the annotation drawn with it: two fruit drawn as one label are one fruit
    for k, ann in enumerate(anns, 1):
        ident = ann.get("id")
        whole = isinstance(ident, int) and not isinstance(ident, bool)
        if ident is not None and not (whole and ident < 2**31):
            # an id is the fruit's label and its truth.json id: one that cannot be (1.5, true, "7", 2**40) was
            # replaced by the annotation's place in silence, and matched to another fruit's truth; none, 0 or a
            # negative one (an exporter's "unset") is numbered by its place, as before
            raise FileFormatError(
                f"{path}: annotation {k} has id {shown(ident)}; a fruit's id is a whole number "
                f"1 to {2**31 - 1} (its mask label), or none (0, -1) to number it by its place"
            )
        label = ident if whole and ident > 0 else k
        if label in idents:
            raise FileFormatError(f"{path}: annotations {idents[label]} and {k} would both be fruit {label} (an id "
                                  "given twice, or an annotation without an id numbered by its place); each fruit "
                                  "needs its own id")  # fmt: skip
        idents[label] = k
    labels = np.zeros((h, w), np.int32)
    for k, (ann, label) in enumerate(zip(anns, idents, strict=True), 1):
        labels[annotation_mask(ann, (h, w), f"{path}: annotation {k}")] = label
    return labels


@dataclass(frozen=True)
class CocoSet:
    """A COCO instance-segmentation file, indexed by image file name.

    Attributes
    ----------
    path : Path
    images : dict
        File name (as written in the file, and its base name) -> the ``images`` entry.
    annotations : dict
        Image id -> its annotations, in file order.
    categories : dict
        Category id -> name.
    """

    path: Path
    images: dict[str, dict[str, Any]]
    annotations: dict[Any, list[dict[str, Any]]]
    categories: dict[int, str]
    #: Base name -> the entries of that base name, where several share it (``row1/0001.png``, ``row2/0001.png``).
    _shared: dict[str, list[dict[str, Any]]] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        by_base: dict[str, list[dict[str, Any]]] = {}
        for entry in self.entries():
            by_base.setdefault(Path(str(entry["file_name"]).replace("\\", "/")).name, []).append(entry)
        self._shared.update({base: found for base, found in by_base.items() if len(found) > 1})

    def annotation_categories(self) -> set[Any]:
        """The ``category_id`` values the annotations use."""
        return {a.get("category_id") for anns in self.annotations.values() for a in anns}

    def check_category(self, category: int | None) -> None:
        """Refuse a category no annotation has (every image would be scored as holding no fruit).

        Raises
        ------
        InputError
            Naming the categories the file does have.
        """
        used = self.annotation_categories()
        if category is None or category in used or not used:
            return
        names = ", ".join(f"{c} ({self.categories[c]})" if c in self.categories else repr(c)
                          for c in sorted(used, key=repr))  # fmt: skip
        raise InputError(f"{self.path}: no annotation has category {category}; the annotations have {names} "
                         "(--category -1 takes every annotation)")  # fmt: skip

    def _wanted(self, entry: dict[str, Any], category: int | None, crowd: bool) -> list[dict[str, Any]]:
        anns = self.annotations.get(_key(entry.get("id")), [])
        return [a for a in anns if (category is None or a.get("category_id") == category)
                and bool(a.get("iscrowd")) == crowd]  # fmt: skip

    def entries(self) -> list[dict[str, Any]]:
        """Every ``images`` entry once, by file name."""
        unique = {id(e): e for e in self.images.values()}
        return sorted(unique.values(), key=lambda e: str(e["file_name"]))

    def image(self, name: str | Path) -> dict[str, Any]:
        """The ``images`` entry of ``name`` (a file name or path; matched on the base name too, and where several
        entries share that base name, on the folders the path ends in: ``.../row2/0001.png`` is ``row2/0001.png``)."""
        key = str(name)
        entry = self.images.get(key)
        if entry is not None and entry["file_name"] != key:
            entry = None  # the base name of an entry's file_name: checked against others of that name below
        shared = self._shared.get(_parts(key)[-1] if _parts(key) else key) if entry is None else None
        if shared:  # before: the first of them, whichever the image was (row2/0001.png got row1/0001.png's fruit)
            given = _parts(key)
            fits = [e for e in shared if _ends_in(given, _parts(e["file_name"]))]
            if len(fits) != 1:
                names = ", ".join(repr(e["file_name"]) for e in shared[:3])
                raise FileFormatError(f"{self.path}: {len(shared)} images are named {_parts(key)[-1]!r} ({names}); "
                                      f"which one {key!r} is cannot be told: name the image by a path ending in "
                                      "its file_name")  # fmt: skip
            entry = fits[0]
        entry = entry or self.images.get(Path(key).name)
        if entry is None:
            raise FileFormatError(f"{self.path}: no image {Path(key).name!r} in this COCO file")
        return entry

    def instances(self, name: str | Path, shape: tuple[int, int], *, category: int | None = 1) -> np.ndarray:
        """The true instance masks of one image.

        Parameters
        ----------
        name : str or Path
            The image's file name (or a path ending in it).
        shape : (h, w)
            The size of the image as read. The entry's ``height`` and ``width``, when given, must agree.
        category : int or None
            Keep annotations of this category id only; ``None`` keeps all.

        Returns
        -------
        (n, h, w) bool, one mask per annotation (masks may overlap). Crowd regions (``iscrowd: 1``) are
        no instances: :meth:`crowd` gives them, as COCO's evaluation ignores them.
        """
        entry, (h, w) = self._entry(name, shape)
        label = f"{self.path}: image {entry.get('file_name')!r}"
        anns = self._wanted(entry, category, crowd=False)
        if len(anns) > MAX_INSTANCES_PER_IMAGE:
            raise FileFormatError(f"{label}: {len(anns)} annotations; at most {MAX_INSTANCES_PER_IMAGE} are read")
        out = np.zeros((len(anns), h, w), bool)
        for k, ann in enumerate(anns):
            out[k] = annotation_mask(ann, (h, w), f"{self.path}: annotation {ann.get('id', k)}")
        return out

    def crowd(self, name: str | Path, shape: tuple[int, int], *, category: int | None = 1) -> tuple[np.ndarray, int]:
        """``(h, w)`` bool: the union of one image's crowd regions (``iscrowd: 1``) of ``category``, and how
        many there are; a prediction lying in them is neither matched nor false, as in COCO's evaluation."""
        entry, (h, w) = self._entry(name, shape)
        anns = self._wanted(entry, category, crowd=True)
        if len(anns) > MAX_INSTANCES_PER_IMAGE:
            raise FileFormatError(f"{self.path}: image {entry.get('file_name')!r}: {len(anns)} crowd regions; at "
                                  f"most {MAX_INSTANCES_PER_IMAGE} are read")  # fmt: skip
        out = np.zeros((h, w), bool)
        for k, ann in enumerate(anns):
            out |= annotation_mask(ann, (h, w), f"{self.path}: annotation {ann.get('id', k)}")
        return out, len(anns)

    def _entry(self, name: str | Path, shape: tuple[int, int]) -> tuple[dict[str, Any], tuple[int, int]]:
        """The entry of ``name`` and the image's ``(h, w)``, checked against the entry's stated size."""
        entry = self.image(name)
        label = f"{self.path}: image {entry.get('file_name')!r}"
        h, w = _check_shape(shape, label)
        if "height" in entry or "width" in entry:
            try:
                stated = (int(entry["height"]), int(entry["width"]))
            except (KeyError, TypeError, ValueError, OverflowError):
                raise FileFormatError(f"{label}: height/width are not whole numbers") from None
            if stated != (h, w):
                turned = (" (turned a quarter: images are read as displayed, an EXIF orientation applied; annotate "
                          "each image as it is displayed, not its stored pixels)")  # fmt: skip
                raise FileFormatError(f"{label} is {stated[1]}x{stated[0]} in the file but {w}x{h} on disk"
                                      f"{turned if stated == (w, h) else ''}")  # fmt: skip
        return entry, (h, w)


def _parts(name: str | Path) -> tuple[str, ...]:
    """A file name's folders and name (``/`` or ``\\`` between them; a leading root or ``.`` dropped), to match
    the end of an image's path."""
    return tuple(p for p in PurePosixPath(str(name).replace("\\", "/")).parts if p not in ("/", "."))


def _ends_in(path: tuple[str, ...], tail: tuple[str, ...]) -> bool:
    return 0 < len(tail) <= len(path) and path[len(path) - len(tail) :] == tail


def _key(value: Any) -> Any:
    """Image ids as dictionary keys: numbers and text as given, anything unhashable as its repr."""
    try:
        hash(value)
    except TypeError:
        return repr(value)
    return value


def read_coco(path: str | Path) -> CocoSet:
    """Read a COCO instance-segmentation JSON (``images``, ``annotations``, optional ``categories``).

    Raises
    ------
    FileFormatError
        When the file is too large, not JSON, or lacks the ``images`` / ``annotations`` lists; for an image
        without an id, two images of one name or id, an annotation for an image id no image has (its fruit would
        be lost from the truth unsaid) or whose ``category_id`` is no id.
    """
    path = Path(path)
    return coco_from_data(path, read_structured(path, what="COCO annotation file", max_bytes=MAX_COCO_BYTES))


def coco_from_data(path: Path, data: Any) -> CocoSet:
    """:func:`read_coco` of a file already parsed (``data``); errors name ``path``."""
    if (
        not isinstance(data, dict)
        or not isinstance(data.get("images"), list)
        or not isinstance(data.get("annotations"), list)
    ):
        raise FileFormatError(f"{path}: expected a COCO object with 'images' and 'annotations' lists")
    images: dict[str, dict[str, Any]] = {}
    ids: dict[Any, str] = {}
    for entry in data["images"]:
        if not isinstance(entry, dict) or not isinstance(entry.get("file_name"), str):
            raise FileFormatError(f"{path}: an 'images' entry has no file_name")
        name = entry["file_name"]
        if name in images and images[name].get("file_name") == name:
            raise FileFormatError(f"{path}: two 'images' entries are named {name!r}")
        if entry.get("id") is None:  # its annotations could never be found: the image would be scored fruitless
            raise FileFormatError(f"{path}: the 'images' entry {name!r} has no id")
        key = _key(entry.get("id"))
        if key in ids:  # both would be scored against the same annotations
            raise FileFormatError(f"{path}: {ids[key]!r} and {name!r} share the image id {entry.get('id')!r}; "
                                  "each image needs its own id")  # fmt: skip
        ids[key] = name
        images[name] = entry
        images.setdefault(Path(name).name, entry)
    annotations: dict[Any, list[dict[str, Any]]] = {}
    for k, ann in enumerate(data["annotations"], 1):
        if not isinstance(ann, dict):
            raise FileFormatError(f"{path}: an 'annotations' entry is not an object")
        category = ann.get("category_id")
        if isinstance(category, bool) or not isinstance(category, (int, str, type(None))):
            raise FileFormatError(f"{path}: annotation {k} has category_id {shown(category)}; a category id is a "
                                  "whole number")  # fmt: skip
        if ann.get("iscrowd") not in (None, 0, 1):  # "0" or "no" as text is truthy: a fruit counted as a crowd
            raise FileFormatError(f"{path}: annotation {k} has iscrowd {shown(ann.get('iscrowd'))}; it is 0 or 1")
        image = _key(ann.get("image_id"))
        if image not in ids:  # a misspelt or missing image_id: that fruit would be lost from the truth unsaid
            raise FileFormatError(f"{path}: annotation {k} is for image id {shown(ann.get('image_id'))}, which no "
                                  "'images' entry has")  # fmt: skip
        annotations.setdefault(image, []).append(ann)
    categories: dict[int, str] = {}
    raw = data.get("categories", [])
    for c in raw if isinstance(raw, list) else []:
        if isinstance(c, dict) and isinstance(c.get("id"), int) and not isinstance(c.get("id"), bool):
            categories[c["id"]] = str(c.get("name", c["id"]))
    return CocoSet(path, images, annotations, categories)


def rle_decode(rle: dict[str, Any]) -> np.ndarray:
    """Decode a COCO RLE (``{"size": [h, w], "counts": list or compressed string}``) to a bool mask.

    The same result as ``pycocotools``; sizes are bounded (:data:`MAX_IMAGE_PIXELS`) before decoding.
    """
    size = rle.get("size") if isinstance(rle, dict) else None
    if not isinstance(size, list | tuple) or len(size) != 2 or "counts" not in rle:  # was TypeError, KeyError
        raise InputError(f"an RLE is {{'size': [h, w], 'counts': ...}}, got {shown(rle)}")
    if any(isinstance(v, bool) or not isinstance(v, int | np.integer) for v in size):  # 7.5 was cut to 7
        raise InputError(f"RLE size must be two whole numbers [h, w], got {shown(size)}")
    h, w = (int(v) for v in size)
    if not (0 < h <= MAX_IMAGE_SIDE and 0 < w <= MAX_IMAGE_SIDE and h * w <= MAX_IMAGE_PIXELS):
        raise ValueError(f"RLE size {w}x{h} is out of range")
    counts = rle["counts"]
    if isinstance(counts, str):
        if len(counts) > 8 * MAX_RLE_RUNS:
            raise ValueError("RLE string too long")
        counts = _rle_string_counts(counts)
    if isinstance(counts, (tuple, np.ndarray)) and np.ndim(counts) == 1:  # handed over by the API
        counts = [c.item() if isinstance(c, np.generic) else c for c in counts]
    if not isinstance(counts, list):
        raise ValueError(
            f"RLE counts must be a list of run lengths or a compressed string, got {type(counts).__name__}"
        )
    if len(counts) > MAX_RLE_RUNS:
        raise ValueError("RLE has too many runs")
    # whole numbers 0 to the image's pixels, each: a float is not cut, a negative run does not cancel a longer
    # one (the sum alone let [19300, -100] through as "adds up to 19200"), a 400-digit one is not an overflow
    bad = next((c for c in counts if isinstance(c, bool) or not isinstance(c, int) or not 0 <= c <= h * w), None)
    if bad is not None:
        raise ValueError(f"RLE counts must be run lengths, whole numbers 0-{h * w}, got {shown(bad, 20)}")
    counts = np.asarray(counts, dtype=np.int64)
    if counts.sum() != h * w:
        raise ValueError(f"RLE counts add up to {counts.sum()}, expected {h * w}")
    values = np.zeros(len(counts), bool)
    values[1::2] = True
    flat = np.repeat(values, counts)
    return flat.reshape(w, h).T  # COCO RLE runs down columns


def _rle_string_counts(s: str) -> list[int]:
    """The LEB128-like string encoding of COCO's ``maskApi.c`` (``rleFrString``)."""
    counts: list[int] = []
    p = 0
    if not s.isascii():
        raise ValueError("a compressed RLE string holds only ASCII characters")
    data = s.encode("ascii")
    while p < len(data):
        x, k, more = 0, 0, True
        while more:
            if p >= len(data) or k > 12:
                raise ValueError("truncated or malformed RLE string")
            c = data[p] - 48
            x |= (c & 0x1F) << (5 * k)
            more = bool(c & 0x20)
            p += 1
            k += 1
            if not more and (c & 0x10):
                x |= -1 << (5 * k)
        if len(counts) > 2:
            x += counts[-2]
        counts.append(x)
    return counts
