-- helpers/ref.lua — reference formulas of docs/fields.md, written in plain
-- Lua independently of the engine, and small assertion helpers for specs.
local M = {}

M.T = 0.5
M.Lg = 96 * math.sqrt(5) / 125

-- Wyvill's falloff g(x) = (1 - x^2)^3 on [0, 1), 0 beyond.
function M.g(x)
  if x < 0 or x >= 1 then return 0 end
  local u = 1 - x * x
  return u * u * u
end

function M.tmax(octaves) return 2 - 2 ^ (1 - octaves) end

-- ---- vectors -------------------------------------------------------------

local function sub(a, b) return {a[1] - b[1], a[2] - b[2], a[3] - b[3]} end
local function add(a, b) return {a[1] + b[1], a[2] + b[2], a[3] + b[3]} end
local function mul(a, s) return {a[1] * s, a[2] * s, a[3] * s} end
local function dot(a, b) return a[1] * b[1] + a[2] * b[2] + a[3] * b[3] end
local function len(a) return math.sqrt(dot(a, a)) end
M.sub, M.add, M.mul, M.dot, M.len = sub, add, mul, dot, len

-- ---- distances ------------------------------------------------------------

function M.dist_point(p, c) return len(sub(p, c)) end

function M.dist_segment(p, a, b)
  local ab, ap = sub(b, a), sub(p, a)
  local l2 = dot(ab, ab)
  local t = l2 > 0 and math.max(0, math.min(1, dot(ap, ab) / l2)) or 0
  return len(sub(p, add(a, mul(ab, t))))
end

function M.dist_box(p, lo, hi)
  local s = 0
  for i = 1, 3 do
    local d = math.max(lo[i] - p[i], 0, p[i] - hi[i])
    s = s + d * d
  end
  return math.sqrt(s)
end

function M.dist_polyline(p, pts)
  local best = math.huge
  for i = 1, #pts - 1 do
    best = math.min(best, M.dist_segment(p, pts[i], pts[i + 1]))
  end
  return best
end

-- Composite cubic Bezier sampled densely into a polyline.
function M.bezier_polyline(ctrl, per_piece)
  per_piece = per_piece or 4000
  local out = {}
  for k = 1, #ctrl - 3, 3 do
    local p0, p1, p2, p3 = ctrl[k], ctrl[k + 1], ctrl[k + 2], ctrl[k + 3]
    for s = (k == 1 and 0 or 1), per_piece do
      local t = s / per_piece
      local u = 1 - t
      local q = {}
      for i = 1, 3 do
        q[i] = u * u * u * p0[i] + 3 * u * u * t * p1[i] + 3 * u * t * t * p2[i]
          + t * t * t * p3[i]
      end
      out[#out + 1] = q
    end
  end
  return out
end

-- Distance to the solid cone: base disc of radius r centred on `base`,
-- apex at `apex`. Works in the (radial q, axial h) half-plane where the
-- cone is the triangle (0,0) (r,0) (0,H).
function M.dist_cone(p, base, apex, r)
  local axis = sub(apex, base)
  local H = len(axis)
  local n = mul(axis, 1 / H)
  local v = sub(p, base)
  local h = dot(v, n)
  local q = len(sub(v, mul(n, h)))
  if h >= 0 and h <= H and q <= r * (1 - h / H) then return 0 end
  local function seg2(px, py, ax, ay, bx, by)
    local abx, aby = bx - ax, by - ay
    local t = ((px - ax) * abx + (py - ay) * aby) / (abx * abx + aby * aby)
    t = math.max(0, math.min(1, t))
    local dx, dy = px - (ax + abx * t), py - (ay + aby * t)
    return math.sqrt(dx * dx + dy * dy)
  end
  return math.min(seg2(q, h, 0, 0, r, 0), seg2(q, h, r, 0, 0, H))
end

-- ---- operators ------------------------------------------------------------

local function gamma(s)
  local u = math.max(0, math.min(1, s))
  return 3 * u * u - 2 * u * u * u
end

function M.smooth_union(fa, fb, r, T)
  T = T or M.T
  local re = r * gamma((fa + fb) / T)
  if re <= 0 then return math.max(fa, fb) end
  local k = math.max(0, 1 - math.abs(fa - fb) / re)
  return math.max(fa, fb) + re * k ^ 3 / 6
end

function M.smooth_intersection(fa, fb, r, T)
  T = T or M.T
  local re = r * gamma(fa * fb / (T * T))
  if re <= 0 then return math.min(fa, fb) end
  local k = math.max(0, 1 - math.abs(fa - fb) / re)
  return math.min(fa, fb) - re * k ^ 3 / 6
end

-- Rotation of v by `deg` degrees about axis (Rodrigues), independent of
-- the binding's matrix code.
function M.rotate(v, axis, deg)
  local k = mul(axis, 1 / len(axis))
  local a = math.rad(deg)
  local c, s = math.cos(a), math.sin(a)
  local kxv = {k[2] * v[3] - k[3] * v[2], k[3] * v[1] - k[1] * v[3],
    k[1] * v[2] - k[2] * v[1]}
  return add(add(mul(v, c), mul(kxv, s)), mul(k, dot(k, v) * (1 - c)))
end

-- ---- assertions -------------------------------------------------------------

-- Asserts |actual - expected| <= tol (absolute) with a readable message.
function M.close(actual, expected, tol, what)
  tol = tol or 1e-9
  if type(actual) ~= "number" or not (math.abs(actual - expected) <= tol) then
    error(string.format("%s: expected %.12g, got %s (tol %g)", what or "value",
      expected, tostring(actual), tol), 2)
  end
end

-- Runs f (which must be defined on a single line of the spec, so its
-- linedefined is the line of the call) and returns the error message and
-- that line; fails if f does not raise.
function M.error_of(f)
  local ok, msg = pcall(f)
  if ok then error("expected an error, the call succeeded", 2) end
  return tostring(msg), debug.getinfo(f, "S").linedefined
end

-- Asserts the message has "<file>:<line>: <fname>: " and every fragment.
function M.check_error(f, file, fname, ...)
  local msg, line = M.error_of(f)
  local head = string.format("%s:%d: %s: ", file, line, fname)
  if not msg:find(head, 1, true) then
    error(string.format("message %q lacks %q", msg, head), 2)
  end
  for _, frag in ipairs({...}) do
    if not msg:find(frag, 1, true) then
      error(string.format("message %q lacks %q", msg, frag), 2)
    end
  end
  return msg
end

-- Central-difference gradient of node at p.
function M.numgrad(node, p, h)
  h = h or 1e-5
  local g = {}
  for i = 1, 3 do
    local a, b = {p[1], p[2], p[3]}, {p[1], p[2], p[3]}
    a[i], b[i] = a[i] + h, b[i] - h
    g[i] = (node:eval(a) - node:eval(b)) / (2 * h)
  end
  return g
end

-- A fresh temporary folder.
function M.tmpdir()
  local name = os.tmpname()
  os.remove(name)
  assert(os.execute("mkdir -p '" .. name .. "'"))
  return name
end

function M.rmdir(name)
  assert(name:match("^/tmp/"), "refusing to remove " .. name)
  os.execute("rm -rf '" .. name .. "'")
end

-- Forgets the run's configuration (what outcrop.configure or the
-- interpreter set, what outcrop.param read, the inputs, the written
-- flag): busted runs every spec file in one Lua state.
function M.reset_config()
  local reg = debug.getregistry()
  for _, k in ipairs{"outcrop.params", "outcrop.seed", "outcrop.scene",
      "outcrop.scene_sha256", "outcrop.outdir", "outcrop.state"} do
    reg[k] = nil
  end
end

-- What the Lua chunk `body` writes to stdout when run by a child lua5.4
-- on `threads` OpenMP threads, with this process's package.cpath (for
-- "the same bytes on one and two threads" checks). `body` must not hold
-- single quotes.
function M.child_output(threads, body)
  local p = assert(io.popen("OMP_NUM_THREADS=" .. threads ..
    " lua5.4 -e 'package.cpath=[[" .. package.cpath .. "]] " .. body .. "'"))
  local out = p:read("a")
  p:close()
  return out
end

return M
