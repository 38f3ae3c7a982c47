//! The page's pieces: escaping, images as data URIs (the page is one file: no server, no
//! network), the image comparator (side by side, a slider, a blink, zoom) and the page shell with
//! its style and script.

use super::ReportError;
use base64::Engine as _;
use std::path::Path;

/// Images larger than this are left out of the page (named, with their size).
const MAX_IMAGE_BYTES: u64 = 32 << 20;

/// `s` safe inside HTML text and attribute values.
pub(crate) fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// `<img>` of the PNG at `path` as a data URI, `alt` its caption; a note where it is too large.
pub(crate) fn img(path: &Path, alt: &str) -> Result<String, ReportError> {
    let len = std::fs::metadata(path)
        .map_err(|e| ReportError::io(path, e))?
        .len();
    if len > MAX_IMAGE_BYTES {
        return Ok(format!(
            "<p class=\"note\">{} left out: {} MiB</p>",
            esc(&path.display().to_string()),
            len >> 20
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| ReportError::io(path, e))?;
    let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
    Ok(format!(
        "<img alt=\"{}\" src=\"data:image/png;base64,{b64}\">",
        esc(alt)
    ))
}

/// A figure: the image and its caption.
pub(crate) fn figure(path: &Path, caption: &str, class: &str) -> Result<String, ReportError> {
    Ok(format!(
        "<figure class=\"{class}\">{}<figcaption>{}</figcaption></figure>",
        img(path, caption)?,
        esc(caption)
    ))
}

/// The comparator: `a` (the expected image) and `b` (the one judged) and any more images (a
/// diff) side by side, with a slider and a blink between `a` and `b`, and zoom (nearest
/// neighbour) for all of them. Its controls work without a server (the page's script).
pub(crate) fn comparator(
    a: (&Path, &str),
    b: (&Path, &str),
    more: &[(&Path, &str)],
) -> Result<String, ReportError> {
    let mut panes = figure(a.0, a.1, "a")? + &figure(b.0, b.1, "b")?;
    for (p, c) in more {
        panes += &figure(p, c, "x")?;
    }
    Ok(format!(
        r#"<div class="cmp" data-mode="side">
<div class="bar"><span class="modes"><button type="button" data-mode="side" class="on">side by side</button><button type="button" data-mode="slider">slider</button><button type="button" data-mode="blink">blink</button></span>
<label>zoom <select class="zoom"><option>1</option><option>2</option><option>4</option><option>8</option></select></label>
<input class="slide" type="range" min="0" max="100" value="50" aria-label="slider position">
<span class="showing"></span></div>
<div class="panes">{panes}</div>
<div class="stack" hidden><img class="sa" alt="{a_alt}"><img class="sb" alt="{b_alt}"></div>
</div>"#,
        a_alt = esc(a.1),
        b_alt = esc(b.1),
    ))
}

/// A two-column table of `(name, value)` rows, values already HTML.
pub(crate) fn table(rows: &[(String, String)]) -> String {
    let mut s = String::from("<table class=\"kv\">");
    for (k, v) in rows {
        s += &format!("<tr><th>{}</th><td>{v}</td></tr>", esc(k));
    }
    s + "</table>"
}

/// The page: `title`, a navigation line, then `body`.
pub(crate) fn page(title: &str, nav: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
<meta name=\"viewport\" content=\"width=device-width\"><title>{t}</title>\
<style>{STYLE}</style></head>\n<body><header><h1>{t}</h1><nav>{nav}</nav></header>\n\
{body}\n<script>{SCRIPT}</script></body></html>\n",
        t = esc(title)
    )
}

const STYLE: &str = r#"
[hidden]{display:none !important}
body{font:14px/1.4 system-ui,sans-serif;margin:0 1.5em 3em;color:#1d1d1f;background:#fafafa}
header{padding:.6em 0;border-bottom:1px solid #ddd}
h1{font-size:1.3em;margin:0}h2{margin-top:1.6em;border-bottom:2px solid #333}h3{margin:1.2em 0 .3em}
nav a{margin-right:1.2em}
.reason{font-family:ui-monospace,monospace;background:#fff3f3;border-left:4px solid #c33;padding:.4em .6em;white-space:pre-wrap;word-break:break-word}
.note{color:#666}
.cmp{margin:.6em 0 1.2em}
.bar{display:flex;gap:1em;align-items:center;margin-bottom:.4em}
.bar button{border:1px solid #888;background:#fff;padding:.2em .7em;cursor:pointer}
.bar button.on{background:#333;color:#fff}
.cmp .slide{display:none}.cmp[data-mode=slider] .slide{display:inline-block;width:14em}
.panes{display:flex;gap:.8em;overflow:auto;max-height:80vh}
figure{margin:0}figcaption{font-size:.9em;color:#444}
img{image-rendering:pixelated;display:block}
.stack{position:relative;overflow:hidden}
.stack img{position:absolute;left:0;top:0;clip-path:inset(0px)}
table{border-collapse:collapse;margin:.4em 0}td,th{border:1px solid #ddd;padding:.15em .5em;text-align:left;font-variant-numeric:tabular-nums}
th{background:#f0f0f0;font-weight:600}
td.pass{background:#e3f6e3}td.fail{background:#fbdcdc;font-weight:600}td.na{color:#888}
.charts{display:flex;flex-wrap:wrap;gap:1em}.charts img{max-width:640px;image-rendering:auto}
svg.pareto{background:#fff;border:1px solid #ccc}svg.pareto circle{cursor:pointer}
svg.pareto circle.sel{stroke:#000;stroke-width:2.5}
.point{border:1px solid #ccc;background:#fff;padding:.5em;margin:.5em 0}
.point .imgs{display:flex;flex-wrap:wrap;gap:.6em}
.legend span{margin-right:1em}
"#;

const SCRIPT: &str = r#"
(function(){
function sizeAll(c){var z=+c.querySelector('.zoom').value;
 c.querySelectorAll('img').forEach(function(i){if(i.naturalWidth){i.style.width=(i.naturalWidth*z)+'px';i.style.height=(i.naturalHeight*z)+'px';}});
 var sa=c.querySelector('.sa'),st=c.querySelector('.stack');
 if(sa.naturalWidth){st.style.width=(sa.naturalWidth*z)+'px';st.style.height=(sa.naturalHeight*z)+'px';}
 document.querySelectorAll('.stack').forEach(snap);}
// The stacked images are layers: at a fractional page position they would be resampled (a
// blurred first row), so every stack is moved onto whole pixels after any change of layout.
function snap(el){el.style.transform='';if(el.hidden)return;var r=el.getBoundingClientRect(),d=devicePixelRatio;
 var dx=(Math.round((r.left+scrollX)*d)/d)-(r.left+scrollX),dy=(Math.round((r.top+scrollY)*d)/d)-(r.top+scrollY);
 el.style.transform='translate('+dx+'px,'+dy+'px)';}
function setMode(c,m){
 c.dataset.mode=m;clearInterval(c._blink);
 c.querySelectorAll('.modes button').forEach(function(b){b.classList.toggle('on',b.dataset.mode===m);});
 var panes=c.querySelector('.panes'),stack=c.querySelector('.stack'),sa=stack.querySelector('.sa'),sb=stack.querySelector('.sb'),show=c.querySelector('.showing');
 var a=c.querySelector('figure.a img'),b=c.querySelector('figure.b img');
 if(!sa.src){sa.src=a.src;sb.src=b.src;sa.onload=sb.onload=function(){sizeAll(c);};}
 panes.hidden=(m!=='side');stack.hidden=(m==='side');show.textContent='';sb.style.clipPath='';sb.style.visibility='';
 if(m==='slider'){slide(c);}
 if(m==='blink'){var on=true;var tick=function(){sb.style.visibility=on?'visible':'hidden';
   c.dataset.showing=on?'b':'a';show.textContent='showing: '+(on?sb.alt:sa.alt);on=!on;};tick();c._blink=setInterval(tick,600);}
 else{delete c.dataset.showing;}
 sizeAll(c);}
function slide(c){var v=c.querySelector('.slide').value,sb=c.querySelector('.sb');
 var x=Math.round(sb.getBoundingClientRect().width*v/100);
 sb.style.clipPath='inset(0px 0px 0px '+x+'px)';c.querySelector('.showing').textContent='left: '+c.querySelector('.sa').alt+' | right: '+sb.alt;}
document.querySelectorAll('.cmp').forEach(function(c){
 c.querySelectorAll('.modes button').forEach(function(b){b.addEventListener('click',function(){setMode(c,b.dataset.mode);});});
 c.querySelector('.zoom').addEventListener('change',function(){sizeAll(c);});
 c.querySelector('.slide').addEventListener('input',function(){slide(c);});
 c.querySelectorAll('img').forEach(function(i){if(i.complete)sizeAll(c);else i.addEventListener('load',function(){sizeAll(c);});});
});
document.querySelectorAll('svg.pareto').forEach(function(svg){
 svg.querySelectorAll('circle[data-point]').forEach(function(p){p.addEventListener('click',function(){
  var box=document.getElementById(svg.dataset.details);
  box.querySelectorAll('.point').forEach(function(d){d.hidden=(d.id!==p.dataset.point);});
  svg.querySelectorAll('circle.sel').forEach(function(q){q.classList.remove('sel');});p.classList.add('sel');});});
});
window.addEventListener('resize',function(){document.querySelectorAll('.stack').forEach(snap);});
})();
"#;
