"""The browsers' own pages (``liansuo serve --web``): the login form, and a refusal. Everything shown is escaped."""

from __future__ import annotations

from html import escape
from typing import Any

from liansuo.kit.printable import printable

STYLE = """
body { background: #0c181f; color: #e0e0e0; font-family: "Roboto Mono", menlo, monospace; display: flex;
       justify-content: center; margin-top: 8vh; }
main { background: #12232d; border: 1px solid #80d0ff; border-radius: 6px; padding: 16px 24px; width: 34em; }
h1 { font-size: 1.2em; color: #80d0ff; }
label { display: block; margin: 10px 0 2px; }
input { width: 100%; box-sizing: border-box; padding: 6px; background: #0c0f12; color: #e0e0e0;
        border: 1px solid #506070; font: inherit; }
input[type=radio] { width: auto; }
button { margin-top: 14px; padding: 8px 24px; background: #1060a0; color: white; border: none; font: inherit; }
.why { color: #ff5050; font-weight: bold; margin-top: 12px; }
.note { color: #a0a0a0; }
a { color: #80d0ff; }
"""


def _page(title: str, body: str) -> str:
    return (f'<!DOCTYPE html>\n<html lang="zh-CN"><head><meta charset="utf-8"><title>{escape(title)}</title>'
            f"<style>{STYLE}</style></head><body><main>{body}</main></body></html>\n")


def seats_line(lobby: dict[str, Any]) -> str:
    """'1 free · 2 taken · 3 taken (away)', as the console's login screen says it."""
    out = []
    for s in lobby.get("seats", []):
        state = "free" if not s.get("taken") else "taken" if s.get("connected") else "taken (away)"
        out.append(f"{s.get('seat')} {state}")
    return " · ".join(out)


def login_page(lobby: dict[str, Any], why: str = "", role: str = "trainee", name: str = "", seat: str = "",
               back: str = "") -> str:
    """The form: a trainee's name and seat, or the instructor's password. ``why``: the last try's refusal;
    ``back``: who this browser is logged in as already (a link to its console)."""
    station = str((lobby.get("station") or {}).get("name", ""))
    lines = [f"<h1>登录 Log in to the classroom{escape(f' · {station}' if station else '')}</h1>"]
    if lobby:
        lines.append(f'<p class="note">seats: {escape(seats_line(lobby))}</p>')
    if back:
        lines.append(f'<p>Logged in as {escape(printable(back))}: <a href="console">back to your console</a></p>')
    checked = ' checked' if role == "instructor" else ""
    lines.append(f"""<form method="post" action="login">
<label><input type="radio" name="role" value="trainee"{'' if checked else ' checked'}> 值班员 trainee</label>
<label for="name">name</label><input id="name" name="name" maxlength="64" autofocus value="{escape(printable(name))}">
<label for="seat">seat</label>
<input id="seat" name="seat" type="number" min="1" max="64" value="{escape(printable(seat))}">
<label><input type="radio" name="role" value="instructor"{checked}> 教员 instructor</label>
<label for="password">password</label><input id="password" name="password" type="password">
<button type="submit" id="connect">Connect</button>
</form>""")
    if why:
        lines.append(f'<p class="why" id="why">{escape(printable(why))}</p>')
    lines.append('<p class="note">The console opens once the login is accepted.</p>')
    return _page("liansuo classroom: log in", "\n".join(lines))


def refusal_page(why: str) -> str:
    return _page("liansuo classroom", f'<h1>liansuo classroom</h1><p class="why" id="why">{escape(printable(why))}</p>'
                                      '<p><a href="./">back to the login</a></p>')
