"""What happened in a run, as plain data and as sentences.

:func:`summarise` turns a finished :class:`~toolkit.runtime.World` into a
JSON-ready dict: for every actor what it did and, if it watched someone, what
it perceived, segmented, recognised and identified. :func:`render_text` prints
that summary for people.
"""

from __future__ import annotations

from typing import Any

from toolkit.runtime import Actor, World

__all__ = ["summarise", "render_text", "describe_character"]


def describe_character(character: Any) -> dict[str, Any]:
    """Components of a character by table, with their plugin names and a short description."""
    out: dict[str, Any] = {"name": character.name, "parts": len(character.body.parts)}
    for key, component in character.components().items():
        entry: dict[str, Any] = {"plugin": component.name}
        describe = getattr(component, "describe", None)
        if callable(describe):
            entry.update(describe())
        out[key] = entry
    return out


def _did(actor: Actor, world: World) -> list[dict[str, Any]]:
    return [
        {"frame": frame, "time": round(frame / world.fps, 3), "movement": r.movement, "reason": r.reason, "imitating": r.imitating}
        for frame, r in actor.performed
    ]


def _watching(actor: Actor, world: World) -> dict[str, Any]:
    mem = actor.memory
    out: dict[str, Any] = {"target": actor.target.id if actor.target else None}
    out["perceived"] = {
        "frames": mem.n if mem else 0,
        "visible_fraction": round(float(mem.visible.mean()), 4) if mem and mem.n else 0.0,
        "frames_with_root": int(mem.visible.any(axis=1).sum()) if mem and mem.n else 0,  # nothing is seen without it
    }
    offset = actor.watch_start
    out["segments"] = [
        {
            "start_frame": offset + e.data["segment"].start,
            "end_frame": offset + e.data["segment"].end,
            "start": round((offset + e.data["segment"].start) / world.fps, 3),
            "end": round((offset + e.data["segment"].end) / world.fps, 3),
        }
        for e in world.events_of("segment_found", actor.id)
    ]
    out["recognised"] = []
    segments = world.events_of("segment_found", actor.id)
    reported = actor.character.matcher.report_details if actor.character.matcher is not None else ()
    for e in world.events_of("movement_recognised", actor.id):
        m = e.data["match"]
        seg = e.data["segment"]
        if seg is None:  # committed early: the segment it belongs to is the next one found
            seg = next((s.data["segment"] for s in segments if s.frame >= e.frame), None)
            fraction = round(m.decided_at / seg.n_frames, 3) if seg is not None and m.decided_at else None
        else:
            fraction = 1.0
        entry = {
            "time": round(e.time, 3),
            "movement": m.movement,
            "confidence": round(float(m.confidence), 3),
            "decided_at": m.decided_at,
            "early": e.data["segment"] is None,
            "fraction": fraction,
        }
        for key in reported:  # what the matcher itself puts in a report (Matcher.report_details)
            if key in m.details:
                entry[key] = m.details[key]
        out["recognised"].append(entry)
    out["imitations_stopped"] = [
        {"time": round(e.time, 3), "movement": e.data["movement"], "reason": e.data["reason"],
         "returning": e.data.get("returning", 0.0)}
        for e in world.events_of("imitation_stopped", actor.id) if e.data["reason"] != "completed"
    ]
    out["behaviours"] = [_behaviour(e.data["behaviour"], e.time, e.data.get("response"))
                         for e in world.events_of("behaviour_identified", actor.id)]
    return out


def _names(value: Any, fallback: str | None = None) -> list[str]:
    """A matcher's detail as a list of names, whatever its shape.

    A motor command graph reports the edges it learned as a list; a posegraph only says that it learned
    (``True``), and the name is then the recognised movement ``fallback``; a single name is a one-item list.
    """
    if isinstance(value, str):
        return [value]
    if isinstance(value, (list, tuple, set, frozenset)):
        return [str(v) for v in value]
    return [fallback] if value and fallback else []


def _edges(names: Any) -> str:
    """Edge names without their subsystem when they share one (``e1, e2``), else in full."""
    names = _names(names)
    if len({n.rsplit(":", 1)[0] for n in names}) > 1:
        return ", ".join(names)
    return ", ".join(n.split(":")[-1] for n in names)


def behaviour_sentence(observer: str, target: str, b: dict[str, Any]) -> str:
    """One identified (or not identified) behaviour as a sentence."""
    if not b["known"]:
        text = f"{observer} does not know why {target} did {b['movement']}"
        response = b.get("response")
        if response == "shrug":
            return text + " and shrugs"
        if response == "imitate":
            return text + f"; {observer} imitates it"
        return text
    path = " > ".join(reversed(b["path"]))
    text = f"{observer} believes {target} did {b['movement']}"
    if b["object"]:
        text += f" for the {b['object']}"
    text += f" ({path})"
    if b["motivation"]:
        text += f", because of {' and '.join(b['motivation'])}"
    if b["goal"]:
        text += f"; {target} wants to be {' and '.join(b['goal'])}"
    if b["prediction"]:
        text += f"; next {target} will {b['prediction'][0]}"
    seen_as = b.get("seen_as", {}).get(b["object"]) if b["object"] else None
    if seen_as:  # what the object looked like to the observer, and why (an action system's details["seen_as"])
        text += f"; the {b['object']} was taken for a {seen_as.replace(': ', ' (', 1)})"
    in_sight = list(b.get("in_sight", {}))
    if len(in_sight) > 1:
        text += f"; the {' and the '.join(in_sight)} were {'both' if len(in_sight) == 2 else 'all'} in {target}'s line of sight"
    for kind, category in b.get("learned", {}).items():
        text += f"; {observer} learns that {kind} is {category}"
    return text


def _behaviour(b: Any, time: float, response: str | None) -> dict[str, Any]:
    return {
        "time": round(time, 3),
        "known": b.known,
        "movement": b.movement,
        "path": list(b.path),
        "motivation": list(b.motivation),
        "goal": list(b.goal),
        "object": b.object,
        "prediction": list(b.prediction),
        "learned": dict(b.learned),
        "response": response,
        "seen_as": {str(k): str(v) for k, v in b.details.get("seen_as", {}).items()} if b.details else {},
        "in_sight": {str(k): float(v) for k, v in b.details.get("in_sight", {}).items()} if b.details else {},
    }


def summarise(world: World, *, name: str = "") -> dict[str, Any]:
    """The run as a JSON-ready dict."""
    actors = []
    for actor in world.actors.values():
        entry: dict[str, Any] = {
            "id": actor.id,
            "character": describe_character(actor.character),
            "file": str(actor.character.file) if actor.character.file else None,
            "did": _did(actor, world),
        }
        if actor.target is not None:
            entry["watching"] = _watching(actor, world)
        actors.append(entry)
    failures = [dict(e.data, actor=e.actor, time=round(e.time, 3)) for e in world.events if e.kind == "plugin_failed"]
    return {
        "scenario": name,
        "plugin_failures": failures,
        "fps": world.fps,
        "frames": world.frame,
        "duration": round(world.time, 3),
        "objects": [{"name": o.name, "kind": o.kind, "position": [round(float(v), 3) for v in o.position]} for o in world.objects.values()],
        "actors": actors,
    }


def _components_line(c: dict[str, Any]) -> str:
    """Every component table of the character format in its order: the plugin, or "-" where there is none (an
    optional table left out: correspondence and layer only when configured, the others always)."""
    from toolkit.character import COMPONENT_TABLES

    parts = []
    for key in COMPONENT_TABLES:
        if key in c:
            parts.append(f"{key} {c[key]['plugin']}")
        elif key not in ("correspondence", "layer"):
            parts.append(f"{key} -")
    return "; ".join(parts)


def render_text(summary: dict[str, Any]) -> str:
    """The summary as lines a person reads: per actor, perceived, segmented, recognised and did."""
    lines = []
    title = summary["scenario"] or "run"
    lines.append(f"{title}: {summary['duration']:.2f} s, {summary['frames']} frames at {summary['fps']:g} fps")
    for obj in summary["objects"]:
        lines.append(f"  object {obj['name']} ({obj['kind']}) at {obj['position']}")
    for f in summary.get("plugin_failures", []):
        lines.append(f"  at {f['time']:.2f}s went on without plugin {f['plugin']!r} ({f['where']}): {f['error']}")
    for a in summary["actors"]:
        c = a["character"]
        lines.append("")
        lines.append(f"{a['id']} ({c['name']}, {c['parts']} parts): {_components_line(c)}")
        did = a["did"]
        if did:
            acts = ", ".join(
                f"{d['movement']} at {d['time']:.2f}s" + (f" (imitating {d['imitating']})" if d["imitating"] else "") for d in did
            )
            lines.append(f"  did: {acts}")
        else:
            lines.append("  did: nothing (stood in its hub pose)")
        w = a.get("watching")
        if not w:
            continue
        p = w["perceived"]
        lines.append(
            f"  perceived {w['target']}: {p['frames']} frames, {100 * p['visible_fraction']:.1f}% of parts visible, "
            f"root seen in {p['frames_with_root']} frames"
        )
        if "segmenter" not in c:
            lines.append("  segmented: no segmenter in this character")
        else:
            segs = ", ".join(f"[{s['start']:.2f}-{s['end']:.2f}s]" for s in w["segments"]) or "none"
            lines.append(f"  segmented: {len(w['segments'])} segment(s) {segs}")
        if "matcher" not in c:
            lines.append("  recognised: no matcher in this character")
        elif any("candidates" in r or "learned" in r for r in w["recognised"]):
            lines.append("  recognised, one line per demonstration:")
            for r in w["recognised"]:
                text = f"    at {r['time']:.2f}s {r['movement'] or 'unknown'}"
                if "candidates" in r:
                    text += f"; candidates {_edges(r['candidates']) or 'none'}"
                if r["early"] and r["fraction"] is not None:
                    text += f"; committed after {100 * r['fraction']:.0f}% of the demonstration"
                if r.get("learned"):  # the edges a motor command graph learned, or (a posegraph) the new movement
                    text += f"; learned {_edges(_names(r['learned'], r['movement']))}"
                    text += " (after a deviation)" if r.get("deviated") else ""
                if r.get("speed") and abs(r["speed"] - 1) > 0.3:
                    text += f"; {r['speed']:.1f}x his own speed"
                lines.append(text)
            for s_ in w["imitations_stopped"]:
                back = f", {s_['returning']:.2f}s back to the last correct node" if s_.get("returning") else ""
                lines.append(f"    at {s_['time']:.2f}s stopped imitating {s_['movement']}: {s_['reason']}{back}")
        else:
            recs = ", ".join(
                (r["movement"] or "unknown") + f" ({r['confidence']:.2f}" + (f", committed {r['decided_at']} frames in" if r["early"] else "") + ")"
                for r in w["recognised"]
            )
            lines.append(f"  recognised: {recs or 'nothing'}")
        for name, g in c.get("motor", {}).get("subsystems", {}).items():
            if g["edges"]:
                lines.append(f"  motor command graph {name}: {g['nodes']} nodes, {g['edges']} edges, active {g['active']}: "
                             + "; ".join(g["commands"]))
        for b in w["behaviours"]:
            lines.append(f"  at {b['time']:.2f}s: " + behaviour_sentence(c["name"], w["target"], b))
    return "\n".join(lines)
