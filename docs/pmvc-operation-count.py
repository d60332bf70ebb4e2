# Operation counts per point for the GPU PMVC kernel (shaders/bind_pmvc.wgsl; R = 32,
# one band per face): triangles tested against each face, set up, and texels of their
# bounds walked per pass, over 200 of the mesh's points. docs/gpu-binding.md quotes it.
# Faces as coords::cubemap::CUBE_FACES (right, up, normal).
import sys, numpy as np
def load(path):
    V=[];F=[]
    for line in open(path):
        t=line.split()
        if not t: continue
        if t[0]=='v': V.append([float(x) for x in t[1:4]])
        elif t[0]=='f':
            idx=[int(x.split('/')[0])-1 for x in t[1:]]
            for k in range(1,len(idx)-1): F.append([idx[0],idx[k],idx[k+1]])
    return np.array(V),np.array(F,dtype=int)
FACES = [  # (right, up, normal)
    ((0, 1, 0), (0, 0, 1), (1, 0, 0)),
    ((0, 0, 1), (0, 1, 0), (-1, 0, 0)),
    ((0, 0, 1), (1, 0, 0), (0, 1, 0)),
    ((1, 0, 0), (0, 0, 1), (0, -1, 0)),
    ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
    ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
]
R=32
def count(points, V, F):
    res=np.zeros(4)
    for x in points:
        P=V[F]-x  # T,3,3
        for (r,u,n) in FACES:
            r=np.array(r,float);u=np.array(u,float);n=np.array(n,float)
            pr=P@r; pu=P@u; pn=P@n
            out=((pn-pr<0).all(1))|((pn+pr<0).all(1))|((pn-pu<0).all(1))|((pn+pu<0).all(1))
            reach=~out
            res[0]+=len(F); res[1]+=reach.sum()
            # bounds of reaching triangles (projection; edges crossing the plane run off)
            texels=0
            for t in np.nonzero(reach)[0]:
                z=pn[t]; xs=pr[t]; ys=pu[t]
                lo=[1e30,1e30]; hi=[-1e30,-1e30]; front=False
                for k in range(3):
                    q=(k+1)%3
                    if z[k]>0:
                        front=True
                        a=xs[k]/z[k]; b=ys[k]/z[k]
                        lo=[min(lo[0],a),min(lo[1],b)]; hi=[max(hi[0],a),max(hi[1],b)]
                    if (z[k]>0)!=(z[q]>0):
                        s=z[k]/(z[k]-z[q]); cx=xs[k]+s*(xs[q]-xs[k]); cy=ys[k]+s*(ys[q]-ys[k])
                        if cx>=0: hi[0]=1e30
                        if cx<=0: lo[0]=-1e30
                        if cy>=0: hi[1]=1e30
                        if cy<=0: lo[1]=-1e30
                if not front or lo[0]>1 or hi[0]<-1 or lo[1]>1 or hi[1]<-1: continue
                res[2]+=1
                f=[max(np.floor((np.clip(lo[i],-1,1)+1)*0.5*R-0.5),0) for i in range(2)]
                l=[min(np.floor((np.clip(hi[i],-1,1)+1)*0.5*R-0.5)+2,R) for i in range(2)]
                texels+=max(l[0]-f[0],0)*max(l[1]-f[1],0)
            res[3]+=texels
    return res/len(points)
# usage: python docs/pmvc-operation-count.py MESH.obj CAGE.obj  (from `pmvc generate`)
if __name__ == "__main__":
    mesh, cage = sys.argv[1:3]
    V, _ = load(mesh)
    CV, CF = load(cage)
    rng = np.random.default_rng(1)
    pts = V[rng.choice(len(V), min(200, len(V)), replace=False)]
    c = count(pts, CV, CF)
    print(f"{mesh}: {len(CF)} cage triangles; per point over 6 faces: {c[0]:.0f} face tests, "
          f"{c[1]:.0f} pass the face test, {c[2]:.0f} with texels on the face, {c[3]:.0f} texels "
          f"of bounds walked per pass ({c[3] / 6144:.2f} per cube-map texel)")
