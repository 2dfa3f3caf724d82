"""Reproducible FMU files: two builds of the same inputs give the same bytes.

Three things made builds differ, and each is fixed here:

- the GUID: pythonfmu draws one at random (uuid1), the C family drew one too. The C family's
  binary holds :func:`structural_guid`: a name-based UUID (uuid5) of the model's structure
  (name, identifier, and each variable's value reference, name, type, causality,
  variability, initial) and the layer's version, the same for every parameter file, so one
  binary serves them all; its model description's GUID (instantiation token) is
  :func:`wire_token`, a uuid5 of that structure and the wire's digest, which its resources
  record too: a host that pairs a model description with another build's resources folder
  is refused (docs/fmus.md, "One wire"). The Python family's
  is :func:`content_guid`: a uuid5 of everything the FMU holds, its parameter file
  included, because its saved states refuse another parameter file by the GUID;
- ``generationDateAndTime``, dropped (optional in FMI 2.0 and 3.0);
- the zip entries' timestamps and permissions: :func:`fix_timestamps` sets every entry to
  ``SOURCE_DATE_EPOCH`` (the reproducible-builds convention) or, without it, to
  1980-01-01 00:00:00 (the earliest a zip can hold), mode 0644 (0755 under ``binaries/``).
"""
import hashlib
import os
import re
import shutil
import time
import uuid
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

__all__ = ["GUID_NAMESPACE", "structural_guid", "wire_token", "content_guid", "stable_description",
           "fixed_date_time", "fix_timestamps"]

GUID_NAMESPACE = uuid.UUID("5b6c3e0e-7d0c-5f43-9a51-736d612d666d")  # sma-fmu's, fixed once
_KINDS = ("Real", "Integer", "Boolean", "String", "Enumeration", "Float64", "Int32", "Int64",
          "UInt64", "Binary")
_DATE = re.compile(rb'\s+generationDateAndTime="[^"]*"')
_GUID = re.compile(rb'(\s(?:guid|instantiationToken)=")([^"]*)(")')


def structural_guid(description, layer_version):
    """``{uuid}`` of the model's structure in ``description`` (modelDescription.xml bytes or
    an Element) and ``layer_version``: start values, descriptions, dates do not count."""
    root = ET.fromstring(description) if isinstance(description, bytes) else description
    parts = [f"layer {layer_version}", f"fmi {root.get('fmiVersion')}",
             f"model {root.get('modelName')}"]
    for kind in ("CoSimulation", "ModelExchange"):
        element = root.find(kind)
        if element is not None:
            parts.append(f"{kind} {element.get('modelIdentifier')}")
    for variable in root.find("ModelVariables"):
        typed = variable.tag if variable.tag in _KINDS else \
            next((child.tag for child in variable if child.tag in _KINDS), "?")
        parts.append(" ".join(f"{key}={variable.get(key)}" for key in
                              ("valueReference", "name", "causality", "variability", "initial"))
                     + f" type={typed}")
    return "{" + str(uuid.uuid5(GUID_NAMESPACE, "\n".join(parts))) + "}"


def wire_token(structure, digest):
    """``{uuid}`` of a C-family build: its ``structure`` (:func:`structural_guid`) and its
    wire's ``digest`` (:func:`~sma_fmu.runtime.wire_identity.wire_digest`)."""
    return "{" + str(uuid.uuid5(GUID_NAMESPACE, f"{structure}\nwire {digest}")) + "}"


def content_guid(fmu_path):
    """``{uuid}`` of everything in the FMU ``fmu_path`` but its GUID and generation date."""
    digest = hashlib.sha256()
    with zipfile.ZipFile(fmu_path) as archive:
        for name in sorted(archive.namelist()):
            data = archive.read(name)
            if name == "modelDescription.xml":
                data = _GUID.sub(rb"\1\3", _DATE.sub(b"", data))
            digest.update(name.encode("utf-8") + b"\0" + hashlib.sha256(data).digest())
    return "{" + str(uuid.uuid5(GUID_NAMESPACE, digest.hexdigest())) + "}"


def stable_description(description, guid):
    """modelDescription.xml ``description`` (bytes) with ``guid`` and no generation date."""
    description = _DATE.sub(b"", description)
    return _GUID.sub(lambda m: m.group(1) + guid.encode("ascii") + m.group(3), description, count=1)


def fixed_date_time():
    """The timestamp every entry gets: ``SOURCE_DATE_EPOCH`` (UTC) if set, else 1980-01-01."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if epoch.isdigit() and int(epoch) >= 315532800:
        return time.gmtime(int(epoch))[:6]
    return (1980, 1, 1, 0, 0, 0)


def _rewrite(fmu_path, change):
    """Rewrite the zip ``fmu_path`` entry by entry: ``change(name, data)`` gives new data."""
    fmu_path = Path(fmu_path)
    temporary = fmu_path.with_suffix(".reproducible.tmp")
    stamp = fixed_date_time()
    with zipfile.ZipFile(fmu_path) as source, \
            zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            if item.is_dir():
                continue
            info = zipfile.ZipInfo(item.filename, stamp)
            info.create_system = 3  # Unix: the mode below is meant
            mode = 0o755 if item.filename.startswith("binaries/") else 0o644
            info.external_attr = (0o100000 | mode) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            target.writestr(info, change(item.filename, source.read(item.filename)))
    shutil.move(str(temporary), str(fmu_path))


def fix_timestamps(fmu_path, guid=None):
    """Give every entry of ``fmu_path`` :func:`fixed_date_time` and a fixed mode (folder
    entries dropped); with ``guid``, also make modelDescription.xml :func:`stable_description`."""
    def change(name, data):
        return stable_description(data, guid) if guid and name == "modelDescription.xml" else data
    _rewrite(fmu_path, change)
