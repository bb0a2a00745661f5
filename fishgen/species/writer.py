"""Write a :class:`Species` back to the VRFish file layout (Appendix A order)."""
from __future__ import annotations

from fishgen.species.model import Species, Vec2


def _n(value: float) -> str:
    return repr(float(value))


def _row(*values: float | str) -> str:
    return " ".join(v if isinstance(v, str) else _n(v) for v in values)


def format_species(sp: Species, colour_name: str = "colour.png", mask_name: str = "mask.png") -> str:
    c, f = sp.caudal, "true false".split()
    flag = lambda b: f[0] if b else f[1]  # noqa: E731
    out = [
        f"//{sp.name}: VRFish species parameter file (written by fishgen)",
        "//description world_scale urgeFactor start_position_3D_point cubesize_t",
        _row(sp.name, sp.world_scale, sp.urge_factor, *sp.start_position, sp.cube_size),
        "//fish_colours_RGB", _row(*sp.colour),
        "//fishshape_subclass BodySections CircleSections textured masked turn_T catchfish_T "
        "[spline x r pairs]",
        " ".join([sp.shape_class, str(sp.body_sections), str(sp.circle_sections), flag(sp.textured),
                  flag(sp.masked), flag(sp.turn_test), flag(sp.catchfish_test)]
                 + [_n(v) for v in sp.shape_params]),
        "//Compression_ratio_of_fish_body: scaleX scaleY scaleZ", _row(*sp.scale),
        "//Caudal Fin",
        "//top_line middle_line top_angle no_of_top_triangles connection_point_x y z rotation_angle "
        "bottom_line bottom_angle no_of_bottom_triangles movement_angle step_size",
        _row(c.top_line, c.middle_line, c.top_angle, c.top_triangles, *c.connection, c.rotation_angle,
             c.bottom_line, c.bottom_angle, c.bottom_triangles, c.movement_angle, c.step_size),
    ]
    vertical_header = ("//startBodySection endBodySection startLength endLength startangle_in_degrees "
                       "proportion")
    for label, fin in (("adiposeFin", sp.adipose), ("dorsalFin", sp.dorsal)):
        out += [f"//{label}", vertical_header,
                _row(fin.start_section, fin.end_section, fin.start_length, fin.end_length, fin.start_angle,
                     fin.proportion)]
    p = sp.pelvic
    out += ["//pelvicFin",
            "//startCircleSection startBodySection endBodySection start_length end_length end_angle "
            "movement_angle step_size",
            _row(p.start_circle, p.start_section, p.end_section, p.start_length, p.end_length, p.end_angle,
                 p.movement_angle, p.step_size)]
    a = sp.anal
    out += ["//analfin", vertical_header,
            _row(a.start_section, a.end_section, a.start_length, a.end_length, a.start_angle, a.proportion)]
    q = sp.pectoral
    out += ["//pectoralfin",
            "//startBodySection startCircleSection no_of_triangles startLength startAngle proportion "
            "version_t movement_angle step_size",
            _row(q.start_section, q.start_circle, q.triangles, q.start_length, q.start_angle, q.proportion,
                 q.version, q.movement_angle, q.step_size)]
    tp = sp.texture_points
    if tp is not None:
        out += ["//texture_file_name black_and_white_version_file_name", f"{colour_name} {mask_name}",
                "//number_of_points_body_points", str(len(tp.body)),
                "//bodySection_no circleSection_no body_texture_points_2D"]
        for k, (u, v) in enumerate(tp.body):
            out.append(f"{k // sp.circle_sections} {k % sp.circle_sections} {_n(u)} {_n(v)}")

        def block(label: str, points: tuple[Vec2, ...]) -> list[str]:
            return [f"//no_of_{label}_texture_points", str(len(points)), "//texture_points_2D"] + \
                [_row(u, v) for u, v in points]
        out += block("caudal", tp.caudal) + ["//transparency_t", _n(sp.transparency)]
        for label in ("dorsal", "adipose", "anal", "pectoral", "pelvic"):
            out += block(label, getattr(tp, label))
    b = sp.behaviour
    if b is None:   # the file format requires the movement records
        raise ValueError(f"species {sp.name!r} has no behaviour to write")
    out += ["//movement of fish", "//initVelocity_vector", _row(*b.initial_velocity),
            "//urge_weightings", "//random center keepaway repelDistance speed changeRate direction",
            _row(b.random, b.center, b.keepaway, b.repel_distance, b.speed, b.change_rate, b.direction),
            "//flee_info", _row(*b.flee)]
    return "\n".join(out) + "\n"
