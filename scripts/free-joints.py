"""Optimal arc-spline counts with joints on the input vertices against joints off them.

Breadth-first search over joint states (vertex, offset along the vertex normal in tolerance units),
pieces continuous (each starts where the previous ends), each piece a line or a circle through its
two joints passing within tol of the vertices and chord midpoints between them (minimax centre on
the joints' bisector by scan + golden section). Offsets [0] = joints on the vertices; the default
set adds +-0.45 and +-0.9 tol. Run ends stay on the vertices. An experiment for
docs/benchmarks.md, not part of the filter:

  python3 -m venv /tmp/v && /tmp/v/bin/pip install numpy
  /tmp/v/bin/python scripts/free-joints.py FILE.gcode TOL RUNS POINTS
(the first RUNS runs of G1 moves at constant Z, each cut to its first POINTS points).
"""
import numpy as np, sys, re
def load(path):
    pts=[]; runs=[]; cur=[]; mode=None; x=y=0.0
    for line in open(path):
        u=line.split(';')[0]; u=re.sub(r'\(.*?\)','',u).upper()
        g=re.findall(r'G0*(\d+)',u)
        if g: mode=int(g[0]) if int(g[0]) in (0,1,2,3) else mode
        X=re.search(r'X(-?[\d.]+)',u); Y=re.search(r'Y(-?[\d.]+)',u); Z=re.search(r'Z(-?[\d.]+)',u)
        if not (X or Y or Z): continue
        nx=float(X.group(1)) if X else x; ny=float(Y.group(1)) if Y else y
        if mode==1 and not Z:
            if not cur: cur=[(x,y)]
            if (nx,ny)!=cur[-1]: cur.append((nx,ny))
        else:
            if len(cur)>2: runs.append(np.array(cur))
            cur=[]
        x,y=nx,ny
    if len(cur)>2: runs.append(np.array(cur))
    return runs
def maxdev(A,B,P):
    # best circle/line through A,B: minimax over centre on bisector, golden search on t in atan space
    m=(A+B)/2; d=B-A; L=np.linalg.norm(d)
    if L==0: return 1e9
    n=np.array([-d[1],d[0]])/L; h=L/2
    dl=np.abs((P-A)@n)  # line deviation
    best=dl.max()
    def f(s):
        t=np.tan(s); c=m+t*n; r=np.hypot(h,t)
        return np.abs(np.linalg.norm(P-c,axis=1)-r).max()
    # scan then golden refine
    ss=np.linspace(-1.5707,1.5707,41); vals=[f(s) for s in ss]; k=int(np.argmin(vals))
    lo=ss[max(k-1,0)]; hi=ss[min(k+1,40)]
    g=(5**.5-1)/2
    a,b=lo,hi; c1=b-g*(b-a); c2=a+g*(b-a); f1=f(c1); f2=f(c2)
    for _ in range(22):
        if f1<f2: b,c2,f2=c2,c1,f1; c1=b-g*(b-a); f1=f(c1)
        else: a,c1,f1=c1,c2,f2; c2=a+g*(b-a); f2=f(c2)
    return min(best,vals[k],f1,f2)
def min_pieces(R, tol, offsets):
    n=len(R)
    # normals at vertices
    t=np.zeros_like(R); t[1:-1]=R[2:]-R[:-2]; t[0]=R[1]-R[0]; t[-1]=R[-1]-R[-2]
    t/=np.linalg.norm(t,axis=1)[:,None]; nrm=np.stack([-t[:,1],t[:,0]],1)
    mids=(R[1:]+R[:-1])/2
    def joint(v,o): return R[v]+offsets[o]*tol*nrm[v]
    def ok(v1,o1,v2,o2):
        P=np.vstack([R[v1+1:v2], mids[v1:v2]]) if v2>v1+1 else mids[v1:v2]
        return maxdev(joint(v1,o1),joint(v2,o2),P)<=tol
    layer={ (0,len(offsets)//2) }; seen=set(layer); k=0
    while True:
        k+=1; nxt=set()
        for (v1,o1) in layer:
            for o2 in range(len(offsets)):
                lo=v1+1; hi=min(n-1,v1+400)
                # gallop
                step=1; good=lo
                while True:
                    j=min(good+step,hi)
                    if j==good: break
                    if ok(v1,o1,j,o2): good=j; step*=2
                    else: hi=j-1; break
                while hi>good:
                    mid=(good+hi+1)//2
                    if ok(v1,o1,mid,o2): good=mid
                    else: hi=mid-1
                if good==n-1:
                    if o2==len(offsets)//2: return k
                    continue
                for v in range(v1+1,good+1):
                    s=(v,o2)
                    if s not in seen: seen.add(s); nxt.add(s)
        layer=nxt
        if not layer: return None
runs=load(sys.argv[1]); tol=float(sys.argv[2]); maxrun=int(sys.argv[3])
pinned=free=0
for R in [r[:int(sys.argv[4])] for r in runs[:maxrun]]:
    if len(R)<3: pinned+=1; free+=1; continue
    a=min_pieces(R,tol,[0.0]); b=min_pieces(R,tol,[-0.9,-0.45,0.0,0.45,0.9])
    pinned+=a; free+=b
    print(len(R),a,b,flush=True)
print('total pinned',pinned,'free',free)
